"""Builders and grouped configuration of `nbv train` (the TorchRL sota-implementations/sac layout).

Defaults follow the paper's Table 1: batch 8, learning rate 5e-4, fixed
temperature alpha 0.2, target networks soft-updated (factor 0.01) every 20
gradient steps, replay buffer of 1e6 transitions, discount 0.99.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import torch
from torchrl.collectors import Collector
from torchrl.data import ListStorage, TensorDictReplayBuffer
from torchrl.data.replay_buffers import RandomSampler
from torchrl.envs import EnvBase, ParallelEnv, RewardSum, TransformedEnv
from torchrl.modules import ProbabilisticActor, ValueOperator
from torchrl.objectives import SACLoss, SoftUpdate

from nbv.agent import NetworkConfig, make_actor, make_critic
from nbv.env import EnvConfig, NBVEnv
from scenes import load_scene


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


@dataclass(frozen=True)
class LoggerConfig:
    """Run folder, logs and checkpoints."""

    out: Path = field(default=None)
    """Run folder (checkpoint.pt, metrics.csv, training.png, tensorboard/, config.json); resumes its
    checkpoint if any."""
    checkpoint_every: int = 500
    """Environment steps between checkpoints (one is always written at the end)."""
    progress: bool = True
    """Show a progress bar."""


@dataclass(frozen=True)
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
    logger: LoggerConfig = LoggerConfig()
    """Logs and checkpoints."""


def make_environment(config: EnvConfig, envs: int, seed: int) -> EnvBase:
    """The training env: an in-process `NBVEnv` or a `ParallelEnv` of spawned workers, returns summed.

    Worker i is seeded `seed + i` and starts its scene cycle at scene i. The scenes are
    loaded once here first, so a bad scene name fails in this process with a clear message
    rather than inside a worker.
    """
    for spec in config.scene:
        load_scene(spec)
    if envs == 1:
        base: EnvBase = NBVEnv(config, 0, seed)
    else:
        base = ParallelEnv(envs, [partial(NBVEnv, config, i, seed + i) for i in range(envs)],
                           mp_start_method="spawn", serial_for_single=True)
    return TransformedEnv(base, RewardSum())


def make_sac_agent(env: EnvConfig, network: NetworkConfig) -> tuple[ProbabilisticActor, ValueOperator]:
    """The actor and one critic (SACLoss clones it into the twin Q networks)."""
    return make_actor(env.history, env.obs_size, network), make_critic(env.history, env.obs_size, network)


def make_loss_module(actor: ProbabilisticActor, critic: ValueOperator,
                     config: OptimConfig) -> tuple[SACLoss, SoftUpdate]:
    """SAC (v2, no state-value network) with twin critics and fixed alpha, and its target updater."""
    loss = SACLoss(actor, critic, num_qvalue_nets=2, loss_function="l2", alpha_init=config.alpha,
                   fixed_alpha=True, action_spec=actor.spec["action"])
    loss.make_value_estimator(gamma=config.gamma)
    return loss, SoftUpdate(loss, tau=config.target_tau)


def make_optimizers(loss: SACLoss, config: OptimConfig) -> tuple[torch.optim.Adam, torch.optim.Adam]:
    """Adam for the actor and for the twin critics (alpha is fixed: no temperature optimiser)."""
    actor = torch.optim.Adam(_trainable(loss.actor_network_params), lr=config.lr)
    critic = torch.optim.Adam(_trainable(loss.qvalue_network_params), lr=config.lr)
    return actor, critic


def _trainable(params) -> list[torch.Tensor]:
    return [p for p in params.values(True, True) if p.requires_grad]


def make_replay_buffer(config: ReplayBufferConfig) -> TensorDictReplayBuffer:
    """Uniform replay over a list storage (grows as filled; sampling uses torch's global RNG)."""
    return TensorDictReplayBuffer(storage=ListStorage(max_size=config.buffer_size), sampler=RandomSampler(),
                                  batch_size=config.batch_size)


def make_collector(env: EnvBase, actor: ProbabilisticActor, config: CollectorConfig,
                   frames_done: int = 0) -> Collector:
    """A collector for the frames still to collect; random actions until `init_random_frames` overall."""
    remaining_random = max(0, config.init_random_frames - frames_done)
    remaining_random = -(-remaining_random // config.frames_per_batch) * config.frames_per_batch
    return Collector(env, actor, frames_per_batch=config.frames_per_batch,
                     total_frames=config.frames - frames_done, init_random_frames=remaining_random,
                     track_traj_ids=False, auto_register_policy_transforms=False)
