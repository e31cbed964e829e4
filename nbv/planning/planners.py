"""View planners behind one interface: the trained policy and the baselines (docs/rl.md).

`Planner.plan(env, views)` returns the viewpoints to capture, in order. The
env (a one-worker `NBVEnv` on the target scene) supplies the allowed ranges,
the start viewpoint, rendering, features and the Bag of Views; the planners
that need no images (random, circle, hemisphere) use only its config. The
interface and the candidate scheme of the greedy planners are in `base.py`.

- `RandomPlanner`: viewpoints drawn uniformly in the allowed ranges.
- `CirclePlanner`: evenly spaced azimuths at the middle radius and elevation.
- `GreedyBoVPlanner`: from the env's start view, at each step render K
  candidate viewpoints drawn uniformly in the ranges and move to the one of
  highest Bag of Views reward (Sec. IV's reward under the env's `bov` config, no learning).
- `HemispherePlanner`: the full-coverage hemisphere scan (Sec. V-B), the
  paper's reference.
- `InfoGainPlanner` (`infogain.py`): greedy on volumetric information gain,
  the unknown voxels a candidate would see in an occupancy grid built from the
  depth of the views flown to (model-free, geometric, no appearance).
- `CoverageOraclePlanner` (`oracle.py`): the views that see the most of the
  true surface among greedy's candidates and a fixed lattice (greedy with
  restarts, then swaps); it uses the ground-truth mesh, so it is an upper-bound
  reference, not a planner a real UAV could run.
- `PolicyPlanner`: a trained SAC actor from the env's start view, acting on
  its distribution's mode (`policy:CHECKPOINT`, deterministic) or on seeded
  draws from it (`policy-sample:CHECKPOINT`, the max-entropy policy SAC
  trained, whose action dimensions the reward does not constrain stay spread).
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np

from common.provenance import config_from_record
from nbv.planning.base import Planner, check_candidates, sample_viewpoints
from nbv.planning.infogain import InfoGainPlanner
from nbv.planning.oracle import CoverageOraclePlanner
from nbv.recon.config import OccupancyConfig
from nbv.rl.agent import make_actor
from nbv.rl.checkpoint import CheckpointError, load_policy
from nbv.rl.config import EnvConfig, NetworkConfig
from nbv.rl.env import NBVEnv
from nbv.rl.rollout import policy_views
from render.scan import HemispherePlan, hemisphere_scan
from render.viewpoint import TWO_PI, Viewpoint


class RandomPlanner(Planner):
    """Uniformly random viewpoints in the allowed ranges (seeded)."""

    name = "random"

    def __init__(self, seed: int = 0, default_views: int = 13) -> None:
        self.seed, self.default_views = seed, default_views

    def plan(self, env: NBVEnv, views: int | None) -> list[Viewpoint]:
        """`views` (default 13, the paper's Fig. 1 count) random viewpoints."""
        count = self.default_views if views is None else views
        return sample_viewpoints(env.config, count, np.random.default_rng(self.seed))


class CirclePlanner(Planner):
    """Evenly spaced azimuths at the middle of the allowed radius and elevation ranges."""

    name = "circle"

    def __init__(self, default_views: int = 13) -> None:
        self.default_views = default_views

    def plan(self, env: NBVEnv, views: int | None) -> list[Viewpoint]:
        """`views` (default 13) viewpoints on one ring."""
        count = self.default_views if views is None else views
        mid = (env.config.low + env.config.high) / 2.0
        return [Viewpoint(float(mid[0]), TWO_PI * k / count, float(mid[2])) for k in range(count)]


class HemispherePlanner(Planner):
    """The full hemisphere scan at the middle radius (288 views with the default camera)."""

    name = "hemisphere"

    def plan(self, env: NBVEnv, views: int | None) -> list[Viewpoint]:
        """Every viewpoint of the scan (`views`, if given, must not be smaller than it)."""
        radius = (env.config.radius_min + env.config.radius_max) / 2.0
        scan = hemisphere_scan(env.config.camera, HemispherePlan(radius=radius))
        if views is not None and views < len(scan):
            raise ValueError(f"the hemisphere scan has {len(scan)} views; --views {views} would cut it")
        return scan


class GreedyBoVPlanner(Planner):
    """Greedy Bag of Views: move to the best of K rendered random candidates at each step."""

    name = "greedy"

    def __init__(self, candidates: int = 8, seed: int = 0, default_views: int = 13) -> None:
        self.candidates = check_candidates("greedy", candidates)
        self.seed, self.default_views = seed, default_views

    def plan(self, env: NBVEnv, views: int | None) -> list[Viewpoint]:
        """The start view, then `views - 1` greedy moves (default 13 views in all)."""
        rng = np.random.default_rng(self.seed)
        env.reset()
        chosen = [env.viewpoint]
        for _ in range((self.default_views if views is None else views) - 1):
            best, best_reward, best_descriptors = None, -math.inf, None
            for view in sample_viewpoints(env.config, self.candidates, rng):
                _, descriptors = env.capture(view)
                reward = copy.deepcopy(env.bov).reward(descriptors, view.azimuth, view.elevation)
                if reward > best_reward:
                    best, best_reward, best_descriptors = view, reward, descriptors
            env.bov.update(best_descriptors, best.azimuth, best.elevation)
            chosen.append(best)
        return chosen


class PolicyPlanner(Planner):
    """A trained SAC policy from the env's start view: its distribution's mode, or seeded draws from it."""

    name = "policy"

    def __init__(self, checkpoint: str | Path, sample: bool = False, seed: int = 0) -> None:
        self.sample, self.seed = sample, seed
        config, weights = load_policy(checkpoint)
        try:
            self.env_config = config_from_record(EnvConfig, config["env"])
            network = config_from_record(NetworkConfig, config["network"])
            self.actor = make_actor(self.env_config.history, self.env_config.obs_size, network)
        except (KeyError, TypeError, ValueError, AttributeError, RuntimeError) as err:
            raise CheckpointError(f"checkpoint {checkpoint}: its config does not fit this toolkit: "
                                  f"{type(err).__name__}: {err}") from err
        try:
            self.actor.load_state_dict(weights)
        except (AttributeError, TypeError, RuntimeError) as err:
            raise CheckpointError(f"checkpoint {checkpoint}: actor weights do not fit: {err}") from err
        self.actor.eval()

    def check_env(self, env: NBVEnv) -> None:
        """Refuse an env whose state or action differs from the one the policy was trained on."""
        for key in ("history", "obs_size", "radius_min", "radius_max", "elevation_min_deg",
                    "elevation_max_deg", "action_mode", "relative_step"):
            trained, now = getattr(self.env_config, key), getattr(env.config, key)
            if now != trained:
                raise ValueError(f"the policy was trained with {key}={trained!r}, the env has {now!r}")

    def plan(self, env: NBVEnv, views: int | None) -> list[Viewpoint]:
        """Act until the episode ends (one pass or the step cap), or for exactly `views` views."""
        self.check_env(env)
        return policy_views(self.actor, env, views, self.sample, self.seed)


POLICY_KINDS = ("policy", "policy-sample")
"""Spec prefixes of a trained policy: acting on its mode, or on seeded draws."""
SHIPPED_POLICY = Path(__file__).with_name("shipped") / "policy.pt"
"""The policy of the default `nbv train` command, shipped with the toolkit (its config, metrics log and
learning curves beside it): what `policy` and `policy-sample` without a checkpoint use."""


def split_policy_spec(spec: str) -> tuple[str, str] | None:
    """(kind, checkpoint) of a `policy[:CHECKPOINT]` or `policy-sample[:CHECKPOINT]` spec (no checkpoint:
    the shipped policy); None for a baseline."""
    kind, sep, checkpoint = spec.partition(":")
    if kind not in POLICY_KINDS:
        return None
    return kind, checkpoint if sep else str(SHIPPED_POLICY)


def make_planner(spec: str, seed: int = 0, candidates: int = 8,
                 occupancy: OccupancyConfig = OccupancyConfig()) -> Planner:
    """A planner by name: random, circle, greedy, hemisphere, infogain, oracle, policy[:CHECKPOINT],
    policy-sample[:CHECKPOINT] (a training checkpoint.pt or a policy.pt; without one, the shipped policy).

    `candidates` is K of greedy, infogain and oracle; `occupancy` is infogain's grid."""
    if policy := split_policy_spec(spec):
        kind, checkpoint = policy
        return PolicyPlanner(checkpoint, sample=kind == "policy-sample", seed=seed)
    if spec == "random":
        return RandomPlanner(seed)
    if spec == "circle":
        return CirclePlanner()
    if spec == "greedy":
        return GreedyBoVPlanner(candidates, seed)
    if spec == "hemisphere":
        return HemispherePlanner()
    if spec == "infogain":
        return InfoGainPlanner(candidates, seed, occupancy)
    if spec == "oracle":
        return CoverageOraclePlanner(candidates, seed)
    raise ValueError(f"unknown planner {spec!r}; use random, circle, greedy, hemisphere, infogain, oracle, "
                     "policy:CHECKPOINT or policy-sample:CHECKPOINT")


def planner_label(spec: str) -> str:
    """A short, file-name-safe label of a planner spec: a policy is named after its run folder."""
    if policy := split_policy_spec(spec):
        kind, checkpoint = policy
        return f"{kind}-{Path(checkpoint).resolve().parent.name}"  # the shipped one: policy-shipped
    return spec
