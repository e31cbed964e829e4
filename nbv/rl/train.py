"""`nbv train`: Soft Actor-Critic over the NBV environment (paper Sec. IV-V-A, Table 1).

The loop, top to bottom: build env, networks, loss, optimisers, buffer;
restore the run folder's checkpoint if there is one; then collect a batch,
store it, take gradient steps (soft-updating the target critics every
`target_update_interval` steps), log, and checkpoint (with `training.png`,
the learning curves so far). With validation buildings, each checkpoint's
actor is first scored on them (`nbv.rl.validate`, `validation.csv`) and
`policy.pt` keeps the best one.

Exact resumption: checkpoints are taken between iterations and hold
everything the rest of the run depends on: networks, optimisers, replay
buffer, counters, torch / NumPy / Python random states and, with one worker
(in-process), the env's own state (episode in progress, render seed counter,
start-view RNG, Bag of Views). So a one-worker run stopped and resumed ends
with the same parameters as one that ran through. With parallel workers the
workers' episodes in flight are lost at a restart: they start new episodes,
seeded `seed + frames done`, and everything else resumes exactly.

Across machines, `--collector ray --collectors K` collects on K Ray actors
(TorchRL's `RayCollector`), each building its own env; the learner, replay
buffer and checkpoints stay here, and a restart loses the actors' episodes in
flight as with parallel workers.
"""

from __future__ import annotations

import csv
import json
import time
from pathlib import Path

import torch
from tensordict import TensorDictBase
from torch.utils.tensorboard import SummaryWriter
from torchrl.data import ReplayBuffer
from torchrl.objectives import SACLoss
from tqdm import tqdm

from common.io import write_json
from common.provenance import config_from_record, config_record
from common.threads import set_torch_threads
from nbv.fanout.executor import run_tasks
from nbv.rl.builders import (
    make_collector,
    make_environment,
    make_loss_module,
    make_optimizers,
    make_ray_collector,
    make_replay_buffer,
    make_sac_agent,
)
from nbv.rl.checkpoint import (
    actor_weights,
    check_compatible,
    checkpoint_config,
    load_checkpoint,
    rng_state,
    save_checkpoint,
    save_policy,
    seed_everything,
    set_rng_state,
)
from nbv.rl.config import TrainConfig
from nbv.rl.env import NBVEnv
from nbv.rl.lattice import lattice_tasks
from nbv.rl.validate import LatticeValidator, validation_env_config
from nbv.viz.figures import plot_training_curves

CHECKPOINT = "checkpoint.pt"
POLICY = "policy.pt"
"""The actor and config alone (a few MB, for planning), written beside every checkpoint; with validation
buildings, only when the checkpoint's actor scores best on them so far."""
VALIDATION_CSV = "validation.csv"
"""One row per validated checkpoint: frames, the score (%) per validation building, their mean, the best."""
RESUMABLE_CHANGES = ("collector.frames", "collector.threads", "logger.out", "logger.checkpoint_every",
                     "logger.progress", "executor.workers", "executor.ray")
"""Settings a resumed run may change, as dotted paths into the nested config record (a difference
anywhere else, e.g. `env.bov.match_cosine` or `env.camera.width`, is refused). Threads change speed, and
at most float rounding: runs recorded before the thread policy (threads 0) resume under its default 1.
Where the lattices are rendered changes nothing but speed."""
CSV_FIELDS = ("frames", "updates", "reward_mean", "episode_return", "episodes", "loss_actor", "loss_qvalue",
              "entropy", "alpha", "collect_s", "update_s")


def with_defaults(saved: dict) -> dict:
    """A recorded run config with the settings added since it was written at their defaults (which
    reproduce the older behaviour, e.g. render settings); as recorded where it does not parse."""
    try:
        return config_record(config_from_record(TrainConfig, saved))
    except (TypeError, ValueError):
        return saved


def train(config: TrainConfig) -> Path:
    """Train (or resume training) into `config.logger.out`; return the checkpoint path.

    `policy.pt` beside it holds the actor alone (what `nbv plan --planner policy:RUN/policy.pt` needs). With
    `--members K` the command trains K seeds (`nbv.rl.members`) and returns the kept member's checkpoint."""
    if config.validation.members > 1:
        from nbv.rl.members import train_members  # it runs this function once per member

        return train_members(config)
    run = Path(config.logger.out)
    run.mkdir(parents=True, exist_ok=True)
    ckpt_path = run / CHECKPOINT
    resumed = load_checkpoint(ckpt_path) if ckpt_path.exists() else None
    if resumed is not None:
        saved = with_defaults(checkpoint_config(resumed, ckpt_path))
        check_compatible(ckpt_path, saved, config_record(config), RESUMABLE_CHANGES)
    write_json(run / "config.json", config_record(config))
    seed = config.collector.seed
    seed_everything(seed)
    set_torch_threads(config.collector.threads)  # recorded: an in-process env keeps this choice

    # Networks, loss, optimisers, replay buffer.
    actor, critic = make_sac_agent(config.env, config.network)
    loss_module, target_updater = make_loss_module(actor, critic, config.optim)
    optim_actor, optim_critic = make_optimizers(loss_module, config.optim)
    buffer = make_replay_buffer(config.replay_buffer)
    frames, updates = 0, 0
    if resumed is not None:
        loss_module.load_state_dict(resumed["loss"])
        optim_actor.load_state_dict(resumed["optim_actor"])
        optim_critic.load_state_dict(resumed["optim_critic"])
        buffer.load_state_dict(resumed["buffer"])
        frames, updates = int(resumed["counters"]["frames"]), int(resumed["counters"]["updates"])
        if frames >= config.collector.frames:
            return ckpt_path  # the budget is already spent: nothing to do

    # The scenes' view lattices, rendered side by side where the executor says; envs then read the cache.
    validator = None
    if config.validation.enabled:
        validator = LatticeValidator(config.env, config.validation, config.network)
    render_lattices(config)
    best = resumed.get("validation") if resumed is not None else None  # {"frames", "score"} so far

    # Environment and collector (random actions until init_random_frames).
    in_process = None  # the env whose state checkpoints carry: one in this process
    if config.collector.collector == "ray":
        collector = make_ray_collector(config.env, actor, config.collector, seed + frames, frames)
    else:
        env = make_environment(config.env, config.collector.envs, seed + frames)
        if config.collector.envs == 1:
            in_process = env.base_env
            if resumed is not None:
                in_process.restore(resumed["env"])  # before the collector, which resets the env
        collector = make_collector(env, actor, config.collector, frames)
    if resumed is not None:
        set_rng_state(resumed["rng"])  # after every builder: construction draws random numbers too

    writer = SummaryWriter(str(run / "tensorboard"))
    csv_path = run / "metrics.csv"
    new_csv = not csv_path.exists()
    updates_per_batch = round(config.collector.frames_per_batch * config.optim.updates_per_frame)
    last_ckpt = frames
    bar = tqdm(total=config.collector.frames, initial=frames, unit="frame", desc=f"train {run.name}",
               disable=not config.logger.progress)
    try:
        with open(csv_path, "a", newline="") as csv_file:
            log = csv.DictWriter(csv_file, CSV_FIELDS)
            if new_csv:
                log.writeheader()
            start = time.perf_counter()
            for batch in collector:
                collect_s = time.perf_counter() - start
                batch = batch.reshape(-1)
                buffer.extend(batch)
                frames += batch.numel()

                # Gradient steps once the random warm-up is over (Table 1 settings).
                start = time.perf_counter()
                losses = {}
                if frames >= config.collector.init_random_frames:
                    for _ in range(updates_per_batch):
                        losses = sac_update(loss_module, optim_actor, optim_critic, buffer.sample(),
                                            config.optim.reward_scale)
                        updates += 1
                        if updates % config.optim.target_update_interval == 0:
                            target_updater.step()
                update_s = time.perf_counter() - start

                done = batch["next", "done"].squeeze(-1)
                returns = batch["next", "episode_reward"][done]
                row = {"frames": frames, "updates": updates,
                       "reward_mean": batch["next", "reward"].mean().item(),
                       "episode_return": returns.mean().item() if done.any() else "",
                       "episodes": int(done.sum()), "collect_s": collect_s, "update_s": update_s, **losses}
                log.writerow(row)
                for key, value in row.items():
                    if key != "frames" and value != "":
                        writer.add_scalar(f"train/{key}", value, frames)
                bar.update(batch.numel())
                bar.set_postfix(reward=f"{row['reward_mean']:.2f}", updates=updates)

                if frames - last_ckpt >= config.logger.checkpoint_every or frames >= config.collector.frames:
                    csv_file.flush()
                    if validator is not None:
                        best = validate_checkpoint(validator, run, config, loss_module.state_dict(),
                                                   {"frames": frames, "updates": updates}, best)
                    plot_training_curves({run.name: csv_path}, run / "training.png")
                    write_checkpoint(ckpt_path, config, loss_module, optim_actor, optim_critic, buffer,
                                     frames, updates, in_process, best)
                    last_ckpt = frames
                start = time.perf_counter()
    finally:
        bar.close()
        writer.close()
        collector.shutdown()
    return ckpt_path


def render_lattices(config: TrainConfig) -> None:
    """Render the training (--lattice) and validation buildings' view lattices not cached yet, side by side
    where the executor says, so envs and members then read the cache instead of each rendering them."""
    tasks = lattice_tasks(config.env) if config.env.lattice.enabled else []
    if config.validation.enabled:
        tasks += lattice_tasks(validation_env_config(config.env, config.validation))
    run_tasks(tasks, config.executor)


def sac_update(loss_module: SACLoss, optim_actor: torch.optim.Optimizer, optim_critic: torch.optim.Optimizer,
               sample: TensorDictBase, reward_scale: float = 1.0) -> dict[str, float]:
    """One SAC gradient step on a replay sample, rewards scaled; a learned alpha steps with the actor."""
    if reward_scale != 1.0:
        sample.set(("next", "reward"), sample["next", "reward"] * reward_scale)
    losses = loss_module(sample)
    optim_critic.zero_grad()
    optim_actor.zero_grad()
    total = losses["loss_actor"] + losses["loss_qvalue"]
    if loss_module.log_alpha.requires_grad:
        total = total + losses["loss_alpha"]
    total.backward()
    optim_critic.step()
    optim_actor.step()
    return {"loss_actor": losses["loss_actor"].item(), "loss_qvalue": losses["loss_qvalue"].item(),
            "entropy": losses["entropy"].item(), "alpha": losses["alpha"].item()}


def validate_checkpoint(validator: LatticeValidator, run: Path, config: TrainConfig, loss_state: dict,
                        counters: dict[str, int], best: dict | None) -> dict:
    """Score the actor on the validation buildings, log the row, and write `policy.pt` when it is the best
    so far (ties keep the earlier actor); return the best {"frames", "score"}. The global random states
    are kept, so a validated run trains exactly as an unvalidated one."""
    state = rng_state()
    scores = validator.score(actor_weights(loss_state))
    set_rng_state(state)
    score = float(sum(scores.values()) / len(scores))
    if best is None or score > best["score"]:
        save_policy(run / POLICY, json.dumps(config_record(config)), loss_state, counters)
        best = {"frames": counters["frames"], "score": score}
    path = run / VALIDATION_CSV
    new = not path.exists()
    with open(path, "a", newline="") as file:
        log = csv.writer(file)
        if new:
            log.writerow(["frames", *scores, "mean", "best_frames"])
        log.writerow([counters["frames"], *(f"{v:.3f}" for v in scores.values()), f"{score:.3f}",
                      best["frames"]])
    return best


def write_checkpoint(path: Path, config: TrainConfig, loss_module: SACLoss,
                     optim_actor: torch.optim.Optimizer, optim_critic: torch.optim.Optimizer,
                     buffer: ReplayBuffer, frames: int, updates: int, env: NBVEnv | None,
                     best: dict | None = None) -> Path:
    """Save everything a resumed run needs (see the module docstring), and beside it the policy file, or
    with validation the best validation score so far (`validate_checkpoint` writes that policy file)."""
    state = {"config": json.dumps(config_record(config)), "loss": loss_module.state_dict(),
             "optim_actor": optim_actor.state_dict(), "optim_critic": optim_critic.state_dict(),
             "buffer": buffer.state_dict(), "counters": {"frames": frames, "updates": updates},
             "rng": rng_state()}
    if env is not None:
        state["env"] = env.snapshot()
    if config.validation.enabled:
        state["validation"] = best
    else:
        save_policy(path.parent / POLICY, state["config"], state["loss"], state["counters"])
    return save_checkpoint(path, state)
