"""Configs of the RL problem and of `nbv train`, grouped by concern (TorchRL sota-implementations/sac).

Light on purpose (no torch, no torchrl): the command line builds its parser
from these classes. `TrainConfig` nests the env (itself nesting the scene
set, camera, render settings and Bag of Views) and one group per training
concern. Defaults follow the paper's Table 1 (batch 8, learning rate 5e-4,
fixed temperature alpha 0.2, target networks soft-updated by 0.01 every 20
gradient steps, replay buffer of 1e6 transitions, discount 0.99).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from nbv.bov.config import BoVConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import TWO_PI
from scenes.spec import SceneSet


@dataclass(frozen=True, kw_only=True)
class EnvConfig:
    """The NBV environment: scenes, camera, allowed viewpoints, episode, Bag of Views."""

    scenes: SceneSet
    """Scene(s) to fly around (give --scene several times); episodes cycle through them."""
    camera: UAVCamera = UAVCamera()
    """The render camera (the resolution the features see)."""
    render: RenderSettings = RenderSettings()
    """How views are rendered."""
    bov: BoVConfig = BoVConfig(ranges=8)
    """The Bag of Views of the reward (paper Sec. IV)."""
    obs_size: int = 64
    """Side of the square grayscale frames the policy sees, pixels."""
    history: int = 5
    """Frames and viewpoints in the state (the paper's tau)."""
    radius_min: float = 1.5
    """Smallest allowed camera distance from the scene centre, metres."""
    radius_max: float = 2.5
    """Largest allowed camera distance from the scene centre, metres."""
    elevation_min_deg: float = 5.0
    """Lowest allowed elevation, degrees."""
    elevation_max_deg: float = 80.0
    """Highest allowed elevation, degrees."""
    max_steps: int = 30
    """Step cap of an episode (truncation)."""
    action_mode: Literal["absolute", "relative", "orbit"] = "absolute"
    """Action meaning: the next viewpoint (paper), a step from the current one, or an azimuth step with
    absolute R and elevation (orbit)."""
    relative_step: float = 0.25
    """Relative and orbit modes: the largest step per action, as a fraction of each range (azimuth: of
    2 pi)."""

    def __post_init__(self) -> None:
        if not 0 < self.radius_min <= self.radius_max:
            raise ValueError(f"need 0 < radius_min <= radius_max, got {self.radius_min}, {self.radius_max}")
        if not -90 < self.elevation_min_deg <= self.elevation_max_deg < 90:
            raise ValueError("need -90 < elevation_min_deg <= elevation_max_deg < 90, got "
                             f"{self.elevation_min_deg}, {self.elevation_max_deg}")
        for name in ("obs_size", "history", "max_steps"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
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


@dataclass(frozen=True)
class NetworkConfig:
    """Sizes of the actor and critic networks."""

    channels: int = 32
    """Channels of the convolution layers (actor and critic)."""
    hidden: int = 128
    """Width of the fully connected layers (the paper's 128)."""
    location_hidden: int = 64
    """Width of the first fully connected layer of the location sub-networks (the paper's 64)."""


@dataclass(frozen=True)
class CollectorConfig:
    """Data collection: budget, parallel workers, batches."""

    frames: int = 12_000
    """Total environment steps of the run (all workers together); 12k took 65 min on 2 cores at 160x120,
    4 spp, OpenCV SIFT (paper_results/planners)."""
    envs: int = 1
    """Parallel environment workers (spawned processes, one renderer each); 1 runs in-process."""
    frames_per_batch: int = 10
    """Environment steps per collected batch (a multiple of --envs)."""
    init_random_frames: int = 100
    """Steps taken with uniformly random actions before the policy acts and learning starts."""
    seed: int = 0
    """Seed of torch, numpy, Python, the envs and the Bag of Views."""
    threads: int = 0
    """Torch CPU threads of the learner; 0: torch's default (one per core). The learner and an in-process
    env take turns, so all cores help: 2 threads halved a batch-8 update on 2 idle cores (95 -> 46 ms)."""

    def __post_init__(self) -> None:
        if min(self.frames, self.envs) < 1 or self.threads < 0:
            raise ValueError(f"frames and envs must be >= 1 and threads >= 0, got {self.frames}, "
                             f"{self.envs}, {self.threads}")
        if self.frames_per_batch < self.envs or self.frames_per_batch % self.envs:
            raise ValueError(f"frames_per_batch ({self.frames_per_batch}) must be a positive multiple of "
                             f"envs ({self.envs})")


@dataclass(frozen=True)
class ReplayBufferConfig:
    """Experience replay."""

    buffer_size: int = 1_000_000
    """Most transitions kept (Table 1); storage grows with use, nothing is preallocated."""
    batch_size: int = 8
    """Transitions per gradient step (Table 1)."""


@dataclass(frozen=True)
class OptimConfig:
    """SAC losses and optimisation (Table 1)."""

    lr: float = 5e-4
    """Adam learning rate of actor and critics."""
    gamma: float = 0.99
    """Discount factor."""
    alpha: float = 0.2
    """Entropy temperature, fixed."""
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


@dataclass(frozen=True, kw_only=True)
class LoggerConfig:
    """Run folder, logs and checkpoints."""

    out: Path
    """Run folder (checkpoint.pt, metrics.csv, training.png, tensorboard/, config.json); resumes its
    checkpoint if any."""
    checkpoint_every: int = 500
    """Environment steps between checkpoints (one is always written at the end)."""
    progress: bool = True
    """Show a progress bar."""


@dataclass(frozen=True, kw_only=True)
class TrainConfig:
    """Everything `nbv train` needs, grouped by concern."""

    env: EnvConfig
    """The environment."""
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
