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
import json
import shutil
from dataclasses import replace
from pathlib import Path

from tqdm import tqdm

from common.io import write_json
from common.provenance import config_record
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_tasks
from nbv.fanout.task import Task
from nbv.rl.checkpoint import copy_policy, load_policy
from nbv.rl.config import MembersConfig, TrainConfig
from nbv.rl.train import CHECKPOINT, CONFIG_JSON, METRICS_CSV, POLICY, TRAINING_PNG, VALIDATION_CSV, train_run
from nbv.viz.figures import plot_training_curves

MEMBERS_CSV = "members.csv"
"""One row per member: member, seed, best_frames, best_score (validation mean, %), kept (1 for the
member whose actor is `policy.pt`)."""


def member_config(config: TrainConfig, member: int) -> TrainConfig:
    """The one-seed run of member `member`: seed S*K + member, folder RUN/member{member}, no members."""
    seed = config.collector.seed * config.members.count + member
    return replace(config, collector=replace(config.collector, seed=seed), members=MembersConfig(),
                   executor=ExecutorConfig(),
                   logger=replace(config.logger, out=Path(config.logger.out) / f"member{member}",
                                  progress=config.logger.progress and config.executor.workers == 1))


def best_validation(path: Path) -> dict[str, float | None]:
    """The {"frames", "score", "metres"} of the actor a run's `policy.pt` holds, from its validation.csv
    (the last row names it; metres None in logs written before they were) rather than from the
    checkpoint, which carries the whole replay buffer."""
    with open(path, newline="") as file:
        rows = list(csv.DictReader(file))
    frames = int(rows[-1]["best_frames"])
    row = next(r for r in rows if int(r["frames"]) == frames)
    metres = row.get("metres")
    return {"frames": frames, "score": float(row["mean"]), "metres": float(metres) if metres else None}


def train_members(config: TrainConfig) -> Path:
    """Train the command's members (`train_run` each, side by side where the executor says; the command
    renders their lattices first) and keep the best-validated actor as `RUN/policy.pt`; return the kept
    member's checkpoint path."""
    run = Path(config.logger.out)
    run.mkdir(parents=True, exist_ok=True)
    write_json(run / CONFIG_JSON, config_record(config))
    members = [member_config(config, k) for k in range(config.members.count)]
    tasks = [Task(f"member {k} (seed {m.collector.seed})", train_run, {"config": m})
             for k, m in enumerate(members)]
    with tqdm(total=len(tasks), unit="member", desc=f"train {run.name}",
              disable=not config.logger.progress) as bar:
        run_tasks(tasks, config.executor, on_done=lambda task: bar.update())
    best = [best_validation(Path(m.logger.out) / VALIDATION_CSV) for m in members]
    rank = config.validation.rank  # within the metres bar first, then score; ties: the lower seed
    kept = max(range(len(members)), key=lambda k: (*rank(best[k]["score"], best[k]["metres"]), -k))
    copy_policy(Path(members[kept].logger.out) / POLICY, run / POLICY, config_record(config))
    with open(run / MEMBERS_CSV, "w", newline="") as file:
        log = csv.writer(file)
        log.writerow(["member", "seed", "best_frames", "best_score", "kept"])
        for k, (m, b) in enumerate(zip(members, best)):
            log.writerow([k, m.collector.seed, b["frames"], f"{b['score']:.3f}", int(k == kept)])
    plot_training_curves({f"member{k} (seed {m.collector.seed})": Path(m.logger.out) / METRICS_CSV
                          for k, m in enumerate(members)}, run / TRAINING_PNG)
    return Path(members[kept].logger.out) / CHECKPOINT


def export_run(run: Path, dest: Path, name: str) -> None:
    """Copy a finished run into `dest` (the shipped policy, `scripts/ship_policy.py`): its policy file (the
    actor and config, `weights_only`-loadable), config.json, training.png and logs (metrics.csv and, when
    validated, validation.csv); for a run of several members, members.csv and each member's config.json
    and logs in memberK/. The run folder in the recorded configs becomes `name` (a relative path), so no
    machine path is written; nothing else changes. A policy that reads the true mesh (`privileged_unseen`)
    cannot fly a real building: refused."""
    config, _ = load_policy(run / POLICY)
    if config["env"].get("privileged_unseen"):
        raise ValueError(f"{run / POLICY} reads the true mesh (privileged_unseen): never shipped")
    config["logger"]["out"] = name
    dest.mkdir(parents=True, exist_ok=True)
    copy_policy(run / POLICY, dest / POLICY, config)
    write_json(dest / CONFIG_JSON, config)
    shutil.copyfile(run / TRAINING_PNG, dest / TRAINING_PNG)
    if not (run / MEMBERS_CSV).is_file():
        copy_logs(run, dest)
        return
    shutil.copyfile(run / MEMBERS_CSV, dest / MEMBERS_CSV)
    for member in sorted(p for p in run.glob("member*") if p.is_dir()):
        recorded = json.loads((member / CONFIG_JSON).read_text())
        recorded["logger"]["out"] = f"{name}/{member.name}"
        (dest / member.name).mkdir(exist_ok=True)
        write_json(dest / member.name / CONFIG_JSON, recorded)
        copy_logs(member, dest / member.name)


def copy_logs(run: Path, dest: Path) -> None:
    """A run's metrics.csv and, if it was validated, its validation.csv."""
    shutil.copyfile(run / METRICS_CSV, dest / METRICS_CSV)
    if (run / VALIDATION_CSV).is_file():
        shutil.copyfile(run / VALIDATION_CSV, dest / VALIDATION_CSV)
