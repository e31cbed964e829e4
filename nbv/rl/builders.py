"""Builders of `nbv train`, one per concern (the TorchRL sota-implementations/sac layout).

Each takes its group of `nbv.rl.config` (defaults: the paper's Table 1, docs/rl.md §8).
"""

from __future__ import annotations

import os
from functools import partial

import torch
from torchrl.collectors import Collector
from torchrl.collectors.distributed import RayCollector
from torchrl.data import ListStorage, TensorDictReplayBuffer
from torchrl.data.replay_buffers import RandomSampler
from torchrl.envs import EnvBase, ParallelEnv, TransformedEnv
from torchrl.modules import ProbabilisticActor, ValueOperator
from torchrl.objectives import SACLoss, SoftUpdate

from nbv.fanout.worker import cap_threads
from nbv.rl.agent import make_actor, make_critic
from nbv.rl.bov_observation import bov_observation_size
from nbv.rl.config import (
    CollectorConfig,
    EnvConfig,
    NetworkConfig,
    OptimConfig,
    ReplayBufferConfig,
    RewardConfig,
)
from nbv.rl.env import NBVEnv
from nbv.rl.episode_return import EpisodeReturn
from render.variant import configure_libllvm

RENDER_THREADS = 1
"""Dr.Jit threads of a process that steps a training env. The RGB pass's pixel filter adds each sample into
several pixels with atomic adds, whose order across threads varies, and with it the last bit of the sums:
on 2 threads 8 of 200 renders of the same 32x24 views differed from the first pass (by 1 ulp in about 90
pixels), now and then one grey level of a frame, after which a run drifts from its resumption (issue 28,
F11). On one thread every render of a view is the same. On the shared 2 cores at a load of 10-12, one
thread rendered as fast as two (160x120 4 spp: 104-147 against 125-128 ms; 320x240 16 spp: 0.86-1.0
against 0.89-1.2 s); on idle cores two are up to twice as fast."""
RAY_COLLECTOR_CPUS = 1
"""CPUs a Ray collector actor asks for, and the threads its Dr.Jit and torch get."""
RAY_COLLECTOR_MEMORY = 1024**3
"""Memory a Ray collector actor reserves: one renderer, one env, a policy copy."""


def make_environment(config: EnvConfig, envs: int, seed: int,
                     reward_terms: RewardConfig = RewardConfig()) -> EnvBase:
    """The training env: an in-process `NBVEnv` or a `ParallelEnv` of spawned workers, returns summed
    (`EpisodeReturn`: a restored episode keeps its return), with the training-only `reward_terms`
    (`TrainConfig.reward`; none by default).

    Worker i is seeded `seed + i` and starts its scene cycle at scene i; the process stepping an env
    renders on one Dr.Jit thread (`training_env`). The scenes are loaded once here first, so a bad scene
    name fails in this process with a clear message rather than inside a worker.
    """
    for spec in config.scenes.specs():
        spec.load()
    if envs == 1:
        base: EnvBase = training_env(config, 0, seed, reward_terms)
    else:
        makers = [partial(training_env, config, i, seed + i, reward_terms) for i in range(envs)]
        base = ParallelEnv(envs, makers, mp_start_method="spawn", serial_for_single=True)
    return TransformedEnv(base, EpisodeReturn())


def training_env(config: EnvConfig, index: int, seed: int, reward_terms: RewardConfig) -> NBVEnv:
    """Env `index` of a training run, in the process that steps it, which renders on `RENDER_THREADS`
    Dr.Jit threads from now on (reproducible renders)."""
    configure_libllvm()  # before Dr.Jit's first import
    import drjit as dr

    dr.set_thread_count(RENDER_THREADS)
    return NBVEnv(config, index, seed, reward_terms)


def make_sac_agent(env: EnvConfig, network: NetworkConfig) -> tuple[ProbabilisticActor, ValueOperator]:
    """The actor and one critic (SACLoss clones it into the twin Q networks)."""
    extra = bov_observation_size(env)
    return (make_actor(env.history, env.obs_size, network, extra),
            make_critic(env.history, env.obs_size, network, extra))


def make_loss_module(actor: ProbabilisticActor, critic: ValueOperator,
                     config: OptimConfig) -> tuple[SACLoss, SoftUpdate]:
    """SAC (v2, no state-value network) with twin critics, fixed or learned alpha, and its target updater."""
    loss = SACLoss(actor, critic, num_qvalue_nets=2, loss_function="l2", alpha_init=config.alpha,
                   fixed_alpha=not config.auto_alpha, target_entropy="auto", action_spec=actor.spec["action"])
    loss.make_value_estimator(gamma=config.gamma)
    return loss, SoftUpdate(loss, tau=config.target_tau)


def make_optimizers(loss: SACLoss, config: OptimConfig) -> tuple[torch.optim.Adam, torch.optim.Adam]:
    """Adam for the actor (and a learned temperature's log alpha) and for the twin critics."""
    alpha = [loss.log_alpha] if config.auto_alpha else []
    actor = torch.optim.Adam(_trainable(loss.actor_network_params) + alpha, lr=config.lr)
    critic = torch.optim.Adam(_trainable(loss.qvalue_network_params), lr=config.lr)
    return actor, critic


def _trainable(params) -> list[torch.Tensor]:
    return [p for p in params.values(True, True) if p.requires_grad]


def make_replay_buffer(config: ReplayBufferConfig) -> TensorDictReplayBuffer:
    """Uniform replay over a list storage (grows as filled; sampling uses torch's global RNG)."""
    return TensorDictReplayBuffer(storage=ListStorage(max_size=config.buffer_size), sampler=RandomSampler(),
                                  batch_size=config.batch_size)


def _random_frames(config: CollectorConfig, frames_done: int) -> int:
    """Random-action frames still to take, rounded up to whole batches."""
    remaining = max(0, config.init_random_frames - frames_done)
    return -(-remaining // config.frames_per_batch) * config.frames_per_batch


def make_collector(env: EnvBase, actor: ProbabilisticActor, config: CollectorConfig,
                   frames_done: int = 0) -> Collector:
    """A collector for the frames still to collect; random actions until `init_random_frames` overall."""
    return Collector(env, actor, frames_per_batch=config.frames_per_batch,
                     total_frames=config.frames - frames_done,
                     init_random_frames=_random_frames(config, frames_done),
                     track_traj_ids=False, auto_register_policy_transforms=False)


def make_worker_env(config: EnvConfig, index: int, seed: int,
                    reward_terms: RewardConfig = RewardConfig()) -> EnvBase:
    """A Ray collector's env, built inside its actor: Dr.Jit and torch capped to the actor's one core
    (`nbv.fanout.worker`), the Mitsuba variant chosen there, returns summed as `make_environment`'s."""
    cap_threads(RAY_COLLECTOR_CPUS)
    return TransformedEnv(NBVEnv(config, index, seed, reward_terms), EpisodeReturn())


def make_ray_collector(env: EnvConfig, actor: ProbabilisticActor, config: CollectorConfig, seed: int,
                       frames_done: int = 0, reward_terms: RewardConfig = RewardConfig()) -> RayCollector:
    """`config.collectors` Ray actors of one env each (collector i seeded `seed + i`, starting at scene i),
    collecting in step: each batch stacks theirs, and they get the actor's weights before every batch.

    Ray runs on the cluster `$RAY_ADDRESS` names, else on a local instance of `collectors` CPUs. Each actor
    asks for one CPU, no GPU and `RAY_COLLECTOR_MEMORY` (TorchRL's defaults ask for a GPU share and 2 GiB).
    """
    for spec in env.scenes.specs():
        spec.load()  # a bad scene name fails here, named, not inside an actor
    ray_init = ({"address": os.environ["RAY_ADDRESS"]} if os.environ.get("RAY_ADDRESS") else
                {"address": "local", "num_cpus": config.collectors, "include_dashboard": False})
    collector = RayCollector(
        [partial(make_worker_env, env, i, seed + i, reward_terms) for i in range(config.collectors)], actor,
        frames_per_batch=config.frames_per_batch, total_frames=config.frames - frames_done,
        init_random_frames=_random_frames(config, frames_done), sync=True, update_after_each_batch=True,
        ray_init_config={**ray_init, "log_to_driver": False},
        remote_configs={"num_cpus": RAY_COLLECTOR_CPUS, "num_gpus": 0, "memory": RAY_COLLECTOR_MEMORY},
        collector_kwargs={"track_traj_ids": False, "auto_register_policy_transforms": False})
    collector.update_policy_weights_()  # connects the weight sync now; later batches re-send the weights
    return collector
