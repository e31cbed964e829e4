"""Configs of the RL problem and of `nbv train`, grouped by concern (TorchRL sota-implementations/sac).

Light on purpose (no torch, no torchrl): the command line builds its parser from these classes.
`TrainConfig` nests the env (itself nesting the scene set, camera, render settings and Bag of Views) and one
group per training concern. Defaults follow the paper's Table 1 (batch 8, learning rate 5e-4, fixed
temperature alpha 0.2, target networks soft-updated by 0.01 every 20 gradient steps, replay buffer of 1e6
transitions, discount 0.99). Training-only reward terms, which read the true mesh, are `TrainConfig`'s
`reward` group, not the env's: an env rebuilt from a trained run's `EnvConfig` (planning, validation,
scoring) cannot inherit them (the one state input that reads it, `privileged_unseen`, is a diagnostic).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from tyro.conf import arg

from common.threads import WORKER_THREADS
from nbv.bov.config import BoVConfig
from nbv.fanout.config import ExecutorConfig
from render.camera import UAVCamera
from render.scan import check_camera_distance
from render.settings import RenderSettings
from render.viewpoint import TWO_PI
from scenes.spec import SceneSet

REWARD_MATCH_COSINE = 0.8
"""The online reward's match cosine c: the value every training preset and selection round
(paper_results/selection) used, kept when refinement's default moved to 0.78 with the detailed look
(docs/bov.md §4); the shipped policy records it."""


@dataclass(frozen=True)
class LatticeConfig:
    """Training on a per-scene view lattice rendered once instead of rendering every step."""

    enabled: Annotated[bool, arg(name="lattice")] = False
    """Snap each viewpoint to the nearest node of a cached per-scene lattice (fast training); evaluation
    and `nbv plan` always render exact viewpoints."""
    lattice_radii: int = 3
    """Lattice nodes along R, spanning [radius_min, radius_max]."""
    lattice_azimuths: int = 36
    """Lattice nodes around the target (10 degree steps at 36)."""
    lattice_elevations: int = 6
    """Lattice nodes along the elevation, spanning [elevation_min_deg, elevation_max_deg]."""

    def __post_init__(self) -> None:
        for name in ("lattice_radii", "lattice_azimuths", "lattice_elevations"):
            if not 1 <= getattr(self, name) <= 360:
                raise ValueError(f"{name} must lie in [1, 360], got {getattr(self, name)}")


@dataclass(frozen=True, kw_only=True)
class EnvConfig:
    """The NBV environment: scenes, camera, allowed viewpoints, episode, Bag of Views."""

    scenes: SceneSet
    """Scene(s) to fly around (give --scene several times); episodes cycle through them."""
    camera: UAVCamera = UAVCamera()
    """The render camera (the resolution the features see)."""
    render: RenderSettings = RenderSettings()
    """How views are rendered."""
    bov: BoVConfig = BoVConfig(ranges=8, match_cosine=REWARD_MATCH_COSINE)
    """The Bag of Views of the reward (paper Sec. IV)."""
    lattice: LatticeConfig = LatticeConfig()
    """Optional view lattice for fast training."""
    obs_size: int = 64
    """Side of the square grayscale frames the policy sees, pixels."""
    history: int = 5
    """Frames and viewpoints in the state (the paper's tau)."""
    radius_min: float = 1.5
    """Smallest allowed camera distance from the scene centre, metres (at least 1: outside the target)."""
    radius_max: float = 2.5
    """Largest allowed camera distance from the scene centre, metres (at most far_m - 1)."""
    elevation_min_deg: float = 5.0
    """Lowest allowed elevation, degrees."""
    elevation_max_deg: float = 80.0
    """Highest allowed elevation, degrees."""
    max_steps: int = 30
    """Step cap of an episode (truncation)."""
    episode_views: int = 0
    """0: an episode ends after one pass around the target (the paper) or at the step cap. N > 0: it ends
    after N views, the start view included, wherever the camera is (a fixed view budget, beyond the
    paper: training then matches a 13-view evaluation instead of stopping after one pass)."""
    action_mode: Literal["absolute", "relative", "orbit", "forward"] = "absolute"
    """Action meaning: the next viewpoint (paper), a step from the current one, an azimuth step with
    absolute R and elevation (orbit), or an azimuth advance of half to all of `relative_step` of a turn
    with absolute R and elevation (forward: never hovering or turning back)."""
    relative_step: float = 0.25
    """Relative, orbit and forward modes: the largest step per action, as a fraction of each range
    (azimuth: of 2 pi)."""
    bov_observation: bool = False
    """Beyond the paper: add to the state a vector of what the Bag of Views has seen (key `bov`,
    `nbv.rl.bov_observation`): each vocabulary's word and descriptor fill, the last view's novelty, the
    views left and the metres flown. It reads only the captured images and the poses flown. Off: the
    paper's state (frames and viewpoints), bit-for-bit."""
    look_map: bool = False
    """Beyond the paper, with `bov_observation`: the `bov` vector ends in a map of the directions the
    episode has looked from, from the poses flown alone (`nbv.rl.look_map`): a memory blank images do not
    empty."""
    privileged_unseen: bool = False
    """A diagnostic, never shipped: the `bov` vector ends in the true unseen surface (`nbv.rl.unseen_map`)."""
    pose_observation: bool = True
    """The state's `viewpoints` (the paper's). Off (beyond the paper): they are zeros, so the networks must
    read where the camera is from the frames (and the Bag of Views vector): a test of whether a policy that
    cannot fly by its poses alone learns to look (issue 26). The env still flies the actions exactly."""

    def __post_init__(self) -> None:
        if not 0 < self.radius_min <= self.radius_max:
            raise ValueError(f"need 0 < radius_min <= radius_max, got {self.radius_min}, {self.radius_max}")
        check_camera_distance("radius_min", self.radius_min, self.camera)
        check_camera_distance("radius_max", self.radius_max, self.camera)
        if not -90 < self.elevation_min_deg <= self.elevation_max_deg < 90:
            raise ValueError("need -90 < elevation_min_deg <= elevation_max_deg < 90, got "
                             f"{self.elevation_min_deg}, {self.elevation_max_deg}")
        for name in ("look_map", "privileged_unseen"):
            if getattr(self, name) and not self.bov_observation:
                raise ValueError(f"{name} extends the Bag of Views vector: it needs bov_observation")
        for name in ("obs_size", "history", "max_steps"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if self.episode_views == 1 or self.episode_views < 0 or self.episode_views > self.max_steps + 1:
            raise ValueError(f"episode_views must be 0 (one pass) or lie in [2, max_steps + 1 = "
                             f"{self.max_steps + 1}], got {self.episode_views}")
        if not 0 < self.relative_step <= 1:
            raise ValueError(f"relative_step must lie in (0, 1], got {self.relative_step}")

    @property
    def low(self) -> np.ndarray:
        """Lower bounds of (R, azimuth, elevation), radians."""
        return np.array([self.radius_min, 0.0, math.radians(self.elevation_min_deg)])

    @property
    def high(self) -> np.ndarray:
        """Upper bounds of (R, azimuth, elevation), radians."""
        return np.array([self.radius_max, TWO_PI, math.radians(self.elevation_max_deg)])

    @property
    def snapping_error(self) -> tuple[float, float, float]:
        """The largest distance of a viewpoint from its lattice node: (R m, azimuth deg, elevation deg)."""
        grid = self.lattice
        half = [(hi - lo) / (2 * (n - 1)) if n > 1 else hi - lo for lo, hi, n in (
            (self.radius_min, self.radius_max, grid.lattice_radii),
            (self.elevation_min_deg, self.elevation_max_deg, grid.lattice_elevations))]
        return half[0], 180.0 / grid.lattice_azimuths, half[1]


@dataclass(frozen=True)
class NetworkConfig:
    """Sizes of the actor and critic networks."""

    channels: int = 32
    """Channels of the convolution layers (actor and critic)."""
    hidden: int = 128
    """Width of the fully connected layers (the paper's 128)."""
    location_hidden: int = 64
    """Width of the first fully connected layer of the location sub-networks (the paper's 64)."""
    actor_frames: bool = True
    """The actor reads the frames (the paper's). Off (beyond the paper; needs --bov-observation) it reads
    the Bag of Views vector and the viewpoints alone, so what it captures reaches it only through the Bag
    of Views; the critic, used in training only, keeps the frames."""

    def __post_init__(self) -> None:
        for name in ("channels", "hidden", "location_hidden"):
            if not 1 <= getattr(self, name) <= 4096:
                raise ValueError(f"network {name} must lie in [1, 4096], got {getattr(self, name)}")


@dataclass(frozen=True)
class CollectorConfig:
    """Data collection: budget, parallel workers, batches."""

    frames: int = 12_000
    """Total environment steps of the run (all workers together); 12k took 65 min on 2 cores at 160x120,
    4 spp, OpenCV SIFT (paper_results/planners)."""
    envs: int = 1
    """Parallel environment workers (spawned processes, one renderer each); 1 runs in-process."""
    collector: Literal["local", "ray"] = "local"
    """Where the envs run: local (this process, or --envs spawned workers) or ray (--collectors Ray actors,
    each building its own env and policy copy, capped to one core; a local Ray instance, or the cluster
    that $RAY_ADDRESS names). The learner stays in this process."""
    collectors: int = 2
    """Ray collectors (--collector ray): actors of one env each, on the cluster's nodes; every batch
    takes frames_per_batch / collectors steps from each."""
    frames_per_batch: int = 10
    """Environment steps per collected batch (a multiple of --envs)."""
    init_random_frames: int = 100
    """Steps taken with uniformly random actions before the policy acts and learning starts."""
    seed: int = 0
    """Seed of torch, numpy, Python, the envs and the Bag of Views."""
    threads: int = WORKER_THREADS
    """Torch CPU threads of the learner (and of an in-process env); 0: torch's default (one per core).
    Default: the thread policy's 1 (common/threads.py). On 2 idle cores 2 threads halved a batch-8 update
    (95 -> 46 ms), but beside the renderer, workers or another job Kornia SIFT ran 50-80x slower on 2
    threads than on 1 (160x120: 1.6 s vs 25 ms per view); give 2 only on cores nothing else uses.
    ParallelEnv workers run 1 thread whatever this says (TorchRL's default, and the policy's)."""

    def __post_init__(self) -> None:
        if min(self.frames, self.envs) < 1 or self.threads < 0:
            raise ValueError(f"frames and envs must be >= 1 and threads >= 0, got {self.frames}, "
                             f"{self.envs}, {self.threads}")
        if self.frames_per_batch < self.envs or self.frames_per_batch % self.envs:
            raise ValueError(f"frames_per_batch ({self.frames_per_batch}) must be a positive multiple of "
                             f"envs ({self.envs})")
        if self.collectors < 1:
            raise ValueError(f"collectors must be >= 1, got {self.collectors}")
        if self.collector == "ray" and self.envs != 1:
            raise ValueError(f"--collector ray runs one env per collector: give --collectors, not --envs "
                             f"({self.envs})")
        if self.collector == "ray" and self.frames_per_batch % self.collectors:
            raise ValueError(f"frames_per_batch ({self.frames_per_batch}) must be a multiple of collectors "
                             f"({self.collectors})")


@dataclass(frozen=True)
class ReplayBufferConfig:
    """Experience replay."""

    buffer_size: int = 1_000_000
    """Most transitions kept (Table 1); storage grows with use, nothing is preallocated."""
    batch_size: int = 8
    """Transitions per gradient step (Table 1)."""

    def __post_init__(self) -> None:
        if self.batch_size < 1:
            raise ValueError(f"batch_size must be >= 1, got {self.batch_size}")
        if self.buffer_size < self.batch_size:
            raise ValueError(f"buffer_size must be >= batch_size ({self.batch_size}), got {self.buffer_size}")


@dataclass(frozen=True)
class OptimConfig:
    """SAC losses and optimisation (Table 1)."""

    lr: float = 5e-4
    """Adam learning rate of actor and critics."""
    gamma: float = 0.99
    """Discount factor."""
    alpha: float = 0.2
    """Entropy temperature: fixed (Table 1), or the starting value with --auto-alpha."""
    auto_alpha: bool = False
    """Learn the temperature (SAC's automatic tuning towards an entropy of -3, one per action dimension)
    instead of keeping it fixed."""
    target_update_interval: int = 20
    """Gradient steps between soft updates of the target critics."""
    target_tau: float = 0.01
    """Soft update factor of the target critics."""
    updates_per_frame: float = 1.0
    """Gradient steps per collected environment step."""
    reward_scale: float = 1.0
    """Rewards are multiplied by this in the losses (logs keep raw rewards): the same as a temperature of
    alpha / reward_scale. Table 1's alpha with 1.0; BoV rewards of about +-20 then leave the entropy term
    too weak to keep the action dimensions the reward ignores spread."""

    def __post_init__(self) -> None:
        for name in ("lr", "alpha", "updates_per_frame", "reward_scale"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be positive and finite, got {value!r}")
        for name in ("gamma", "target_tau"):
            value = getattr(self, name)
            if not 0 < value <= 1:
                raise ValueError(f"{name} must lie in (0, 1], got {value!r}")
        if self.target_update_interval < 1:
            raise ValueError(f"target_update_interval must be >= 1, got {self.target_update_interval}")


@dataclass(frozen=True)
class ValidationConfig:
    """Checkpoint selection on validation buildings (beyond the paper): at every checkpoint the policy's mode
    flies `validation_views` views from `validation_episodes` seeded start views on each validation building's
    view lattice, scored by the visible coverage of the true surface (`nbv.rl.validate`); `policy.pt` keeps
    the best-scoring actor instead of the last. Off when no building is given."""

    validation_scenes: tuple[str, ...] = ()
    """Validation buildings (never training or test buildings); none: no validation, `policy.pt` is the
    last actor."""
    validation_episodes: int = 3
    """Start views per validation building (seeds 0 .. N-1, the same at every checkpoint)."""
    validation_views: int = 13
    """Views per validation episode, the start view included."""
    validation_points: int = 20_000
    """True-surface samples of the coverage score per building."""
    validation_max_metres: float = 0.0
    """Beyond the paper: an actor whose validation flights average more metres than this (along the
    viewing shell) is kept as `policy.pt`, or as a command's member, only while no actor within it has
    been; 0: no bar, the best score wins (issue 26's metres check: 1.5x the tuned ring's metres)."""
    validation_exact: bool = False
    """Beyond the paper: fly the validation episodes on exact renders at the training settings instead of
    the buildings' view lattices (views x episodes x buildings renders a checkpoint: 156 at the defaults),
    so the score and the metres are those the exact-render checks measure (on the lattice the nearest
    node's frame moves the actions: paper_results/selection/round17)."""
    validation_keep: bool = False
    """Also write every validated actor to `validated/policy_FRAMES.pt` in the run folder, so a checkpoint
    can be chosen afterwards by other checks than the lattice score (exact renders, metres, blank images:
    `scripts/looks_eval.py`)."""

    def __post_init__(self) -> None:
        for name in ("validation_episodes", "validation_views", "validation_points"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if not self.validation_max_metres >= 0:
            raise ValueError(f"validation_max_metres must be >= 0, got {self.validation_max_metres}")

    def rank(self, score: float, metres: float | None) -> tuple[bool, float]:
        """The order actors are kept in: within `validation_max_metres` (or no bar, or metres unknown)
        first, then the higher score."""
        within = self.validation_max_metres <= 0 or metres is None or metres <= self.validation_max_metres
        return within, score

    @property
    def enabled(self) -> bool:
        """Whether checkpoints are scored on validation buildings."""
        return bool(self.validation_scenes)


@dataclass(frozen=True)
class RewardConfig:
    """Training-only reward terms, beyond the paper, added to the Bag of Views reward. The coverage term reads
    the true mesh, so only the training env gets them (`nbv.rl.builders.make_environment`); an `NBVEnv` built
    from an `EnvConfig` alone (planning, validation, scoring) has none."""

    coverage: Annotated[float, arg(name="coverage-reward")] = 0.0
    """Weight W of a geometric reward term: W x the share of the target's surface samples that the new
    view is the first of its episode to see (ground truth: training only). 0: the paper's reward alone."""

    flight: Annotated[float, arg(name="flight-reward")] = 0.0
    """Weight W of a flight-cost term: minus W x the metres of the leg to the new view along the viewing
    shell (`nbv.flight.shell_path`), beyond the paper. 0: no flight cost."""

    flight_allowance: Annotated[float, arg(name="flight-allowance")] = 0.0
    """Metres of an episode's flight free of `flight_excess` (a hinge: `nbv.rl.flight_cost`). 0: none."""

    flight_excess: Annotated[float, arg(name="flight-excess-reward")] = 0.0
    """Weight W of the hinge: minus W x each metre flown past `flight_allowance` (reward and teacher)."""

    imitation: Annotated[float, arg(name="imitation")] = 0.0
    """Weight W of an imitation term in the actor's loss (beyond the paper): W x the squared distance between
    the actor's mode and the privileged teacher's action (`nbv.rl.expert`: the candidate step that sees the
    most true surface not seen yet, less the flight term), labelled in every state the training env visits."""

    teacher_horizon: Annotated[int, arg(name="teacher-horizon")] = 3
    """How many times over the teacher flies each candidate action to score it (`nbv.rl.expert`); 0: to the
    end of the episode's view budget."""

    teacher_discount: Annotated[float, arg(name="teacher-discount")] = 0.9
    """The weight, per step ahead, of a later view's new samples and leg against the next view's."""

    teacher_tolerance: Annotated[float, arg(name="teacher-tolerance")] = 0.0
    """Coverage points within which the teacher's candidate steps count as ties (`nbv.rl.expert.near_best`):
    the imitation term pulls the actor's mode to the nearest of them. 0: to the teacher's one best step."""

    def __post_init__(self) -> None:
        if self.teacher_horizon < 0:
            raise ValueError(f"teacher_horizon must be >= 0, got {self.teacher_horizon}")
        if not 0 < self.teacher_discount <= 1:
            raise ValueError(f"teacher_discount must lie in (0, 1], got {self.teacher_discount}")
        for flag, value in (("teacher_tolerance", self.teacher_tolerance), ("imitation", self.imitation),
                            ("coverage_reward", self.coverage), ("flight_reward", self.flight),
                            ("flight_excess_reward", self.flight_excess),
                            ("flight_allowance", self.flight_allowance)):
            if not 0 <= value < math.inf:
                raise ValueError(f"{flag} must be finite and >= 0, got {value}")


@dataclass(frozen=True)
class MembersConfig:
    """Several training seeds per command (`nbv.rl.members`)."""

    count: Annotated[int, arg(name="members")] = 1
    """Independent training runs of the command (seeds seed*members .. seed*members + members-1, in
    RUN/memberK/, side by side where --workers says); `policy.pt` is the best-validated actor of them all
    (`nbv.rl.members`). 1: one run, in RUN itself."""

    def __post_init__(self) -> None:
        if self.count < 1:
            raise ValueError(f"members must be >= 1, got {self.count}")


@dataclass(frozen=True, kw_only=True)
class LoggerConfig:
    """Run folder, logs and checkpoints."""

    out: Path
    """Run folder (checkpoint.pt, metrics.csv, training.png, tensorboard/, config.json); resumes its
    checkpoint if any."""
    checkpoint_every: int = 500
    """Environment steps between checkpoints (one is always written at the end); each is validated when
    validation buildings are given."""
    progress: bool = True
    """Show a progress bar."""


@dataclass(frozen=True, kw_only=True)
class TrainConfig:
    """Everything `nbv train` needs, grouped by concern."""

    env: EnvConfig
    """The environment."""
    reward: RewardConfig = RewardConfig()
    """Training-only reward terms (the training env's alone)."""
    collector: CollectorConfig = CollectorConfig()
    """Data collection."""
    replay_buffer: ReplayBufferConfig = ReplayBufferConfig()
    """Experience replay."""
    optim: OptimConfig = OptimConfig()
    """Losses and optimisers."""
    network: NetworkConfig = NetworkConfig()
    """Network sizes."""
    logger: LoggerConfig
    """Logs and checkpoints."""
    validation: ValidationConfig = ValidationConfig()
    """Checkpoint selection on validation buildings (off by default; on in the `default` preset)."""
    members: MembersConfig = MembersConfig()
    """Training seeds of the command, the best-validated kept (one by default; three in the `default`
    preset)."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the scenes' view lattices are rendered before training (--lattice), and where the members
    train (--members): this process, local workers or Ray."""

    def __post_init__(self) -> None:
        if not self.network.actor_frames and not self.env.bov_observation:
            raise ValueError("an actor without frames (--no-actor-frames) reads the Bag of Views vector: "
                             "it needs --bov-observation")
        if self.members.count > 1 and not self.validation.enabled:
            raise ValueError(f"members ({self.members.count}) are compared on validation buildings: give "
                             "--validation-scenes")


MOVED_KEYS = {("env", "coverage_reward"): ("reward", "coverage"),
              ("validation", "members"): ("members", "count")}
"""Run-record keys that moved group since records were first written: (old group, key) -> (new group, key).
The shipped policy and paper_results/online/policies record the old layout."""


def upgrade_record(record: dict) -> dict:
    """A `TrainConfig` record (a run's config.json, a checkpoint's or policy file's config) in today's
    layout: each of `MOVED_KEYS` moved to its new group (a copy; today's records come back equal)."""
    record = {key: dict(value) if isinstance(value, dict) else value for key, value in record.items()}
    for (old_group, old_key), (new_group, new_key) in MOVED_KEYS.items():
        group = record.get(old_group)
        if isinstance(group, dict) and old_key in group:
            value = group.pop(old_key)
            if isinstance(record.setdefault(new_group, {}), dict):
                record[new_group].setdefault(new_key, value)
    return record
