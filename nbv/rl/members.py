"""Several training seeds in one `nbv train` command, the best on the validation buildings kept.

SAC on the Bag of Views reward lands in different places from different seeds: three seeds of one
setting scored 86.6, 81.9 and 69.7 % on the held-out buildings (docs/rl.md §11), and no checkpoint of
the weakest run was good, so checkpoint selection within a run cannot help it. With `--members K`,
`nbv train --seed S` trains K independent runs, seeded S*K .. S*K + K-1 (so the members of two
commands never share a seed), each in `RUN/memberK/` with its validated checkpoints, side by side
where the executor says; `RUN/policy.pt` is the actor whose validation score is the best over all of
them, recorded with the command's own config, so the file is what the command makes. `members.csv`
lists each member's best score and which one was kept; `training.png` overlays the members' curves.
"""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path

from tqdm import tqdm

from common.io import write_json
from common.provenance import config_record
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_tasks
from nbv.fanout.task import Task
from nbv.rl.checkpoint import copy_policy
from nbv.rl.config import TrainConfig
from nbv.rl.train import CHECKPOINT, POLICY, VALIDATION_CSV, render_lattices, train
from nbv.viz.figures import plot_training_curves

MEMBERS_CSV = "members.csv"
"""One row per member: member, seed, best_frames, best_score (validation mean, %), kept (1 for the
member whose actor is `policy.pt`)."""


def member_config(config: TrainConfig, member: int) -> TrainConfig:
    """The one-seed run of member `member`: seed S*K + member, folder RUN/member{member}, no members."""
    seed = config.collector.seed * config.validation.members + member
    return replace(config, collector=replace(config.collector, seed=seed),
                   validation=replace(config.validation, members=1), executor=ExecutorConfig(),
                   logger=replace(config.logger, out=Path(config.logger.out) / f"member{member}",
                                  progress=config.logger.progress and config.executor.workers == 1))


def best_validation(path: Path) -> dict[str, float]:
    """The {"frames", "score"} of the actor a run's `policy.pt` holds, from its validation.csv (the last
    row names it) rather than from the checkpoint, which carries the whole replay buffer."""
    with open(path, newline="") as file:
        rows = list(csv.DictReader(file))
    frames = int(rows[-1]["best_frames"])
    return {"frames": frames, "score": next(float(r["mean"]) for r in rows if int(r["frames"]) == frames)}


def train_members(config: TrainConfig) -> Path:
    """Train the command's members (lattices first, once) and keep the best-validated actor as
    `RUN/policy.pt`; return the kept member's checkpoint path."""
    run = Path(config.logger.out)
    run.mkdir(parents=True, exist_ok=True)
    write_json(run / "config.json", config_record(config))
    render_lattices(config)
    members = [member_config(config, k) for k in range(config.validation.members)]
    tasks = [Task(f"member {k} (seed {m.collector.seed})", train, {"config": m})
             for k, m in enumerate(members)]
    with tqdm(total=len(tasks), unit="member", desc=f"train {run.name}",
              disable=not config.logger.progress) as bar:
        run_tasks(tasks, config.executor, on_done=lambda task: bar.update())
    best = [best_validation(Path(m.logger.out) / VALIDATION_CSV) for m in members]
    kept = max(range(len(members)), key=lambda k: (best[k]["score"], -k))  # ties: the lower seed
    copy_policy(Path(members[kept].logger.out) / POLICY, run / POLICY, config_record(config))
    with open(run / MEMBERS_CSV, "w", newline="") as file:
        log = csv.writer(file)
        log.writerow(["member", "seed", "best_frames", "best_score", "kept"])
        for k, (m, b) in enumerate(zip(members, best)):
            log.writerow([k, m.collector.seed, b["frames"], f"{b['score']:.3f}", int(k == kept)])
    plot_training_curves({f"member{k} (seed {m.collector.seed})": Path(m.logger.out) / "metrics.csv"
                          for k, m in enumerate(members)}, run / "training.png")
    return Path(members[kept].logger.out) / CHECKPOINT
