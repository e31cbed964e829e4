"""The training loop of one `nbv train` run: Soft Actor-Critic over the NBV env (paper Sec. IV-V-A, Table 1).

`train_run` trains one seed; the command (`nbv.rl.command.train_command`) renders the view lattices
first and runs several seeds (`nbv.rl.members`). The loop, top to bottom: build env, networks, loss,
optimisers, buffer; restore the run folder's checkpoint if there is one; then collect a batch, store
it, take gradient steps (soft-updating the target critics every `target_update_interval` steps), log,
and checkpoint (with `training.png`, the learning curves so far). With validation buildings, each
checkpoint's actor is first scored on them (`nbv.rl.validate`, `validation.csv`) and `policy.pt`
keeps the best one.

Exact resumption: checkpoints are taken between iterations and hold
everything the rest of the run depends on: networks, optimisers, replay
buffer, counters, torch / NumPy / Python random states and, with one worker
(in-process), the env's own state (episode in progress, render seed counter,
start-view RNG, Bag of Views, the episode's return so far). So a one-worker
run stopped or killed and resumed ends with the same parameters, replay
buffer and logs as one that ran through: on resume, `metrics.csv` and
`validation.csv` are cut back to the checkpoint (`nbv.rl.run_logs`), and the
env's process renders on one Dr.Jit thread (`nbv.rl.builders.RENDER_THREADS`). With parallel workers the
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
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import torch
from tensordict import TensorDictBase
from torch.utils.tensorboard import SummaryWriter
from torchrl.data import ReplayBuffer
from torchrl.modules import ProbabilisticActor, ValueOperator
from torchrl.objectives import SACLoss, SoftUpdate
from tqdm import tqdm

from common.io import write_json
from common.provenance import config_from_record, config_record
from common.threads import set_torch_threads
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
from nbv.rl.config import OptimConfig, TrainConfig, upgrade_record
from nbv.rl.env import NBVEnv
from nbv.rl.expert import CANDIDATES, EXPERT_KEY, EXPERT_SET_KEY
from nbv.rl.run_logs import trim_log, validation_fields
from nbv.rl.validate import Validator, mean_score
from nbv.viz.figures import plot_training_curves

CHECKPOINT = "checkpoint.pt"
CONFIG_JSON = "config.json"
"""The run's whole config (`common.provenance.config_record`)."""
METRICS_CSV = "metrics.csv"
"""One row per collected batch (`CSV_FIELDS`)."""
TRAINING_PNG = "training.png"
"""The learning curves so far, drawn at each checkpoint."""
POLICY = "policy.pt"
"""The actor and config alone (a few MB, for planning), written beside every checkpoint; with validation
buildings, only when the checkpoint's actor scores best on them so far."""
VALIDATED = "validated"
"""The run's folder of every validated actor's policy file (`ValidationConfig.validation_keep`)."""
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
IMITATION_FIELD = "loss_imitation"
"""The extra `metrics.csv` column of a run with an imitation term (`RewardConfig.imitation`)."""


def log_fields(config: TrainConfig) -> tuple[str, ...]:
    """The run's `metrics.csv` columns: `CSV_FIELDS`, and the imitation loss where it has one."""
    return CSV_FIELDS + ((IMITATION_FIELD,) if config.reward.imitation else ())


def with_defaults(saved: dict) -> dict:
    """A recorded run config in today's layout (`upgrade_record`) with the settings added since it was
    written at their defaults (which reproduce the older behaviour, e.g. render settings); as recorded,
    upgraded, where it does not parse."""
    saved = upgrade_record(saved)
    try:
        return config_record(config_from_record(TrainConfig, saved))
    except (TypeError, ValueError):
        return saved


def train_run(config: TrainConfig) -> Path:
    """Train (or resume training) one run into `config.logger.out`; return the checkpoint path.

    `policy.pt` beside it holds the actor alone (what `nbv plan --planner policy:RUN/policy.pt` needs).
    One seed: `nbv train` itself (`nbv.rl.command.train_command`) renders the lattices and runs members."""
    run = Path(config.logger.out)
    run.mkdir(parents=True, exist_ok=True)
    resumed = resume_state(run / CHECKPOINT, config)
    write_json(run / CONFIG_JSON, config_record(config))
    seed_everything(config.collector.seed)
    set_torch_threads(config.collector.threads)  # recorded: an in-process env keeps this choice

    # Networks, loss, optimisers, replay buffer.
    actor, critic = make_sac_agent(config.env, config.network)
    learner = make_learner(actor, critic, config)
    frames, updates = learner.restore(resumed) if resumed is not None else (0, 0)
    trim_log(run / METRICS_CSV, frames, log_fields(config))  # the logs end where the checkpoint does
    trim_log(run / VALIDATION_CSV, frames, validation_fields(config.validation.validation_scenes))
    if frames >= config.collector.frames:
        return run / CHECKPOINT  # the budget is already spent: nothing to do
    validator = None
    if config.validation.enabled:
        validator = Validator(config.env, config.validation, config.network)
    best = resumed.get("validation") if resumed is not None else None  # {"frames", "score"} so far

    # Environment and collector (random actions until init_random_frames).
    collector, in_process = make_run_collector(config, actor, frames, resumed)
    if resumed is not None:
        set_rng_state(resumed["rng"])  # after every builder: construction draws random numbers too

    updates_per_batch = round(config.collector.frames_per_batch * config.optim.updates_per_frame)
    last_ckpt = frames
    try:
        with RunLog(run, config, frames) as log:
            start = time.perf_counter()
            for batch in collector:
                collect_s = time.perf_counter() - start
                batch = batch.reshape(-1)
                learner.buffer.extend(batch)
                frames += batch.numel()

                start = time.perf_counter()
                losses = {}
                if frames >= config.collector.init_random_frames:  # learning starts after the warm-up
                    losses, updates = learner.gradient_steps(updates_per_batch, updates, config.optim,
                                                             config.reward.imitation)
                log.log_batch(batch, frames, updates, losses, collect_s, time.perf_counter() - start)

                if frames - last_ckpt >= config.logger.checkpoint_every or frames >= config.collector.frames:
                    best = checkpoint_run(run, config, learner, frames, updates, in_process, validator, best,
                                          log)
                    last_ckpt = frames
                start = time.perf_counter()
    finally:
        collector.shutdown()
    return run / CHECKPOINT


def resume_state(path: Path, config: TrainConfig) -> dict | None:
    """The run folder's checkpoint if there is one, refused (`CheckpointError`) when its recorded settings
    differ from `config` beyond `RESUMABLE_CHANGES`."""
    if not path.exists():
        return None
    resumed = load_checkpoint(path)
    saved = with_defaults(checkpoint_config(resumed, path))
    check_compatible(path, saved, config_record(config), RESUMABLE_CHANGES)
    return resumed


@dataclass(frozen=True)
class Learner:
    """What a run trains and checkpoints: the SAC loss module (actor, twin critics and their targets), the
    target updater, the two optimisers and the replay buffer."""

    loss: SACLoss
    target_updater: SoftUpdate
    optim_actor: torch.optim.Optimizer
    optim_critic: torch.optim.Optimizer
    buffer: ReplayBuffer

    def restore(self, resumed: dict) -> tuple[int, int]:
        """Load a checkpoint's learner state; return its (frames, updates) counters."""
        self.loss.load_state_dict(resumed["loss"])
        self.optim_actor.load_state_dict(resumed["optim_actor"])
        self.optim_critic.load_state_dict(resumed["optim_critic"])
        self.buffer.load_state_dict(resumed["buffer"])
        return int(resumed["counters"]["frames"]), int(resumed["counters"]["updates"])

    def gradient_steps(self, steps: int, updates: int, optim: OptimConfig,
                       imitation: float = 0.0) -> tuple[dict[str, float], int]:
        """`steps` SAC gradient steps on replay samples (`sac_update`, Table 1 settings, with the imitation
        weight), the target critics soft-updated every `target_update_interval` updates; the last step's
        losses and the update count."""
        losses = {}
        for _ in range(steps):
            losses = sac_update(self.loss, self.optim_actor, self.optim_critic, self.buffer.sample(),
                                optim.reward_scale, imitation)
            updates += 1
            if updates % optim.target_update_interval == 0:
                self.target_updater.step()
        return losses, updates


def make_learner(actor: ProbabilisticActor, critic: ValueOperator, config: TrainConfig) -> Learner:
    """The SAC loss over `actor` and `critic`, its optimisers and an empty replay buffer."""
    loss_module, target_updater = make_loss_module(actor, critic, config.optim)
    optim_actor, optim_critic = make_optimizers(loss_module, config.optim)
    return Learner(loss_module, target_updater, optim_actor, optim_critic,
                   make_replay_buffer(config.replay_buffer))


def make_run_collector(config: TrainConfig, actor: ProbabilisticActor, frames: int,
                       resumed: dict | None) -> tuple[Iterable[TensorDictBase], NBVEnv | None]:
    """The run's collector for the frames still to collect, and its env when that runs in this process
    (one worker: its state is restored from `resumed` and checkpointed); envs seeded `seed + frames`."""
    seed = config.collector.seed + frames
    if config.collector.collector == "ray":
        return make_ray_collector(config.env, actor, config.collector, seed, frames, config.reward), None
    env = make_environment(config.env, config.collector.envs, seed, config.reward)
    in_process = env.base_env if config.collector.envs == 1 else None
    if in_process is not None and resumed is not None:
        in_process.restore(resumed["env"])  # before the collector, which resets the env
    return make_collector(env, actor, config.collector, frames), in_process


class RunLog:
    """A run's training logs: `metrics.csv` (appended to when resuming, after `trim_log` cut it back to the
    checkpoint), TensorBoard scalars under `tensorboard/` (those past the checkpoint `frames` purged),
    the progress bar, and the learning curves `training.png` at each checkpoint."""

    def __init__(self, run: Path, config: TrainConfig, frames: int) -> None:
        self.run, self.csv_path = run, run / METRICS_CSV
        # Steps past the checkpoint were logged by the run that died after it: TensorBoard drops them.
        self._writer = SummaryWriter(str(run / "tensorboard"), purge_step=frames + 1)
        new_csv = not self.csv_path.is_file() or self.csv_path.stat().st_size == 0
        self._file = open(self.csv_path, "a", newline="")
        self._csv = csv.DictWriter(self._file, log_fields(config))
        if new_csv:
            self._csv.writeheader()
        self._bar = tqdm(total=config.collector.frames, initial=frames, unit="frame",
                         desc=f"train {run.name}", disable=not config.logger.progress)

    def __enter__(self) -> RunLog:
        return self

    def __exit__(self, *exc) -> None:
        self._bar.close()
        self._writer.close()
        self._file.close()

    def log_batch(self, batch: TensorDictBase, frames: int, updates: int, losses: dict[str, float],
                  collect_s: float, update_s: float) -> None:
        """One `metrics.csv` row (and TensorBoard scalars) for a collected batch and its updates."""
        done = batch["next", "done"].squeeze(-1)
        returns = batch["next", "episode_reward"][done]
        row = {"frames": frames, "updates": updates, "reward_mean": batch["next", "reward"].mean().item(),
               "episode_return": returns.mean().item() if done.any() else "",
               "episodes": int(done.sum()), "collect_s": collect_s, "update_s": update_s, **losses}
        self._csv.writerow(row)
        for key, value in row.items():
            if key != "frames" and value != "":
                self._writer.add_scalar(f"train/{key}", value, frames)
        self._bar.update(batch.numel())
        self._bar.set_postfix(reward=f"{row['reward_mean']:.2f}", updates=updates)

    def plot(self) -> None:
        """Flush `metrics.csv` and draw `training.png` from it."""
        self._file.flush()
        plot_training_curves({self.run.name: self.csv_path}, self.run / TRAINING_PNG)


def checkpoint_run(run: Path, config: TrainConfig, learner: Learner, frames: int, updates: int,
                   env: NBVEnv | None, validator: Validator | None, best: dict | None,
                   log: RunLog) -> dict | None:
    """Validate the actor (with validation buildings), draw the curves and write the checkpoint (and the
    policy file); return the best validation {"frames", "score"} so far."""
    if validator is not None:
        best = validate_checkpoint(validator, run, config, learner.loss.state_dict(),
                                   {"frames": frames, "updates": updates}, best)
    log.plot()
    write_checkpoint(run / CHECKPOINT, config, learner.loss, learner.optim_actor, learner.optim_critic,
                     learner.buffer, frames, updates, env, best)
    return best


CANDIDATE_ACTIONS = torch.from_numpy(CANDIDATES).float()
"""The teacher's candidate steps as a float32 tensor, the actor's dtype (built once, not at every update)."""


def mode_distance(actor: ProbabilisticActor, sample: TensorDictBase) -> torch.Tensor:
    """Mean over the sample's states of the squared distance between the actor's mode and the teacher's
    action (`nbv.rl.expert`), summed over the action's values; where the states hold the teacher's
    near-ties (`EXPERT_SET_KEY`), the distance to the nearest of them."""
    mode = actor.get_dist(sample.select(*actor.in_keys)).deterministic_sample
    if EXPERT_SET_KEY not in sample.keys():
        return ((mode - sample[EXPERT_KEY]) ** 2).sum(-1).mean()
    distances = ((mode.unsqueeze(-2) - CANDIDATE_ACTIONS.to(mode.dtype)) ** 2).sum(-1)
    return distances.masked_fill(~sample[EXPERT_SET_KEY], torch.inf).amin(-1).mean()


def imitation_loss(loss_module: SACLoss, sample: TensorDictBase) -> torch.Tensor:
    """`mode_distance` of the loss module's actor (its trained parameters) over a replay sample."""
    with loss_module.actor_network_params.to_module(loss_module.actor_network, preserve_module_state=False):
        return mode_distance(loss_module.actor_network, sample)


def sac_update(loss_module: SACLoss, optim_actor: torch.optim.Optimizer, optim_critic: torch.optim.Optimizer,
               sample: TensorDictBase, reward_scale: float = 1.0, imitation: float = 0.0) -> dict[str, float]:
    """One SAC gradient step on a replay sample, rewards scaled; a learned alpha steps with the actor; with
    `imitation` W > 0 the actor's loss adds W x `imitation_loss`."""
    if reward_scale != 1.0:
        sample.set(("next", "reward"), sample["next", "reward"] * reward_scale)
    losses = loss_module(sample)
    optim_critic.zero_grad()
    optim_actor.zero_grad()
    total = losses["loss_actor"] + losses["loss_qvalue"]
    if loss_module.log_alpha.requires_grad:
        total = total + losses["loss_alpha"]
    imitated = {}
    if imitation:
        bc = imitation_loss(loss_module, sample)
        total = total + imitation * bc
        imitated = {IMITATION_FIELD: bc.item()}
    total.backward()
    optim_critic.step()
    optim_actor.step()
    return {"loss_actor": losses["loss_actor"].item(), "loss_qvalue": losses["loss_qvalue"].item(),
            "entropy": losses["entropy"].item(), "alpha": losses["alpha"].item(), **imitated}


def validated_policy(run: Path, frames: int) -> Path:
    """The policy file of the actor validated at `frames` (`ValidationConfig.validation_keep`)."""
    return run / VALIDATED / f"policy_{frames:06d}.pt"


def validate_checkpoint(validator: Validator, run: Path, config: TrainConfig, loss_state: dict,
                        counters: dict[str, int], best: dict | None) -> dict:
    """Score the actor on the validation buildings, log the row, and write `policy.pt` when it is the best
    so far (`ValidationConfig.rank`: within the metres bar, then score; ties keep the earlier actor);
    return the best {"frames", "score", "metres"}. The global random states
    are kept, so a validated run trains exactly as an unvalidated one."""
    state = rng_state()
    scores, metres = validator.score_and_metres(actor_weights(loss_state))
    set_rng_state(state)
    score = mean_score(scores)
    rank, record = config.validation.rank, json.dumps(config_record(config))
    if config.validation.validation_keep:
        kept = validated_policy(run, counters["frames"])
        kept.parent.mkdir(exist_ok=True)
        save_policy(kept, record, loss_state, counters)
    if best is None or rank(score, metres) > rank(best["score"], best.get("metres")):
        save_policy(run / POLICY, record, loss_state, counters)
        best = {"frames": counters["frames"], "score": score, "metres": metres}
    path = run / VALIDATION_CSV
    new = not path.is_file() or path.stat().st_size == 0
    with open(path, "a", newline="") as file:
        log = csv.writer(file)
        if new:
            log.writerow(validation_fields(list(scores)))
        log.writerow([counters["frames"], *(f"{v:.3f}" for v in scores.values()), f"{score:.3f}",
                      best["frames"], f"{metres:.3f}"])
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
