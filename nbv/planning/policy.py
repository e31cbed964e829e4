"""The trained policy as a planner: a SAC actor from the start view, on its mode or on seeded draws.

`policy:CHECKPOINT` acts on its action distribution's mode (deterministic);
`policy-sample:CHECKPOINT` on seeded draws from it (the max-entropy policy SAC
trained, whose action dimensions the reward does not constrain stay spread).
Without a checkpoint, the shipped policy (`registry.SHIPPED_POLICY`); `policy-paper` flies the paper
preset's shipped actor (`registry.SHIPPED_PAPER_POLICY`) on its mode.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from common.provenance import config_from_record
from nbv.planning.base import Planner
from nbv.planning.registry import SHIPPED_PAPER_POLICY, SHIPPED_POLICY
from nbv.rl.agent import make_actor
from nbv.rl.bov_observation import bov_observation_size
from nbv.rl.checkpoint import CheckpointError, load_policy
from nbv.rl.config import EnvConfig, NetworkConfig
from nbv.rl.env import NBVEnv
from nbv.rl.rollout import policy_views
from nbv.rl.validate import evaluation_env_config
from render.viewpoint import Viewpoint

if TYPE_CHECKING:
    from nbv.planning.config import PlanSettings
    from nbv.planning.world import PlanningWorld


class PolicyPlanner(Planner):
    """A trained SAC policy from the start view: its distribution's mode, or seeded draws from it.

    It flies its own `NBVEnv` (`planning_env`: its training settings on the plan's scene) on the
    world's view source, so its renders count on the plan's clock.
    """

    name = "policy"

    def __init__(self, checkpoint: str | Path, sample: bool = False, seed: int = 0,
                 blank_images: bool = False) -> None:
        self.sample, self.seed, self.checkpoint = sample, seed, checkpoint
        self.blank_images = blank_images  # an evaluation-time test: every captured image replaced by a blank
        config, weights = load_policy(checkpoint)
        try:
            self.env_config = config_from_record(EnvConfig, config["env"])
            network = config_from_record(NetworkConfig, config["network"])
            self.actor = make_actor(self.env_config.history, self.env_config.obs_size, network,
                                    bov_observation_size(self.env_config))
        except (KeyError, TypeError, ValueError, AttributeError, RuntimeError) as err:
            raise CheckpointError(f"checkpoint {checkpoint}: its config does not fit this toolkit: "
                                  f"{type(err).__name__}: {err}") from err
        try:
            self.actor.load_state_dict(weights)
        except (AttributeError, TypeError, RuntimeError) as err:
            raise CheckpointError(f"checkpoint {checkpoint}: actor weights do not fit: {err}") from err
        self.actor.eval()

    def planning_env(self, own: EnvConfig) -> EnvConfig:
        """Its training settings on the plan's scenes, rendering exact viewpoints in the plan's Mitsuba
        variant: a policy trained on a view lattice plans without it. Its episode ends where the protocol
        says (one pass, or the view budget), whatever budget it trained with, and no reward reads the
        true mesh."""
        render = replace(self.env_config.render, variant=own.render.variant)
        return evaluation_env_config(self.env_config, own.scenes, render=render, episode_views=0)

    def check_env(self, config: EnvConfig) -> None:
        """Refuse env settings whose state or action differ from those the policy was trained on."""
        for key in ("history", "obs_size", "radius_min", "radius_max", "elevation_min_deg",
                    "elevation_max_deg", "action_mode", "relative_step"):
            trained, now = getattr(self.env_config, key), getattr(config, key)
            if now != trained:
                raise ValueError(f"the policy was trained with {key}={trained!r}, the env has {now!r}")

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """Act until the episode ends (one pass or the step cap), or for exactly `views` views, in an env
        on the world's settings and view source (the env draws the world's start view)."""
        self.check_env(world.env)
        config = world.env
        if config.bov_observation and views is not None and 2 <= views <= config.max_steps + 1:
            config = replace(config, episode_views=views)  # its views-left entry counts down this budget
        env = NBVEnv(config, seed=world.seed, source=world.source, blank_images=self.blank_images)
        try:
            return policy_views(self.actor, env, views, self.sample, self.seed)
        except ValueError as err:  # e.g. a NaN action from finite but diverged weights: name the file
            raise ValueError(f"policy {self.checkpoint}: {err}") from err


def policy_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> PolicyPlanner:
    """The registry's `policy`: the checkpoint's actor (none: the shipped one) on its mode."""
    return PolicyPlanner(checkpoint or SHIPPED_POLICY, sample=False, seed=seed,
                         blank_images=settings.blank_images)


def paper_policy_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> PolicyPlanner:
    """The registry's `policy-paper`: the paper preset's shipped actor on its mode (takes no checkpoint)."""
    return PolicyPlanner(SHIPPED_PAPER_POLICY, sample=False, seed=seed, blank_images=settings.blank_images)


def sampled_policy_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> PolicyPlanner:
    """The registry's `policy-sample`: the checkpoint's actor (none: the shipped one) on seeded draws."""
    return PolicyPlanner(checkpoint or SHIPPED_POLICY, sample=True, seed=seed,
                         blank_images=settings.blank_images)
