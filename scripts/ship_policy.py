"""Copy a finished `nbv train` run into the package as the shipped policy (issue 11).

Writes DEST/policy.pt (the actor and config, `weights_only`-loadable), config.json, training.png and
the logs: metrics.csv and, for a validated run, validation.csv; for a run of several members
(`--members`), members.csv and each member's config.json, metrics.csv and validation.csv in memberK/.
The run's output folder in the recorded configs is replaced by `--name` (a relative path), so no
machine path is committed; nothing else changes.

    python scripts/ship_policy.py --run runs/default --dest nbv/planning/shipped --name runs/default
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

from common.io import write_json
from nbv.rl.checkpoint import copy_policy, load_policy
from nbv.rl.members import MEMBERS_CSV


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", type=Path, required=True)
    parser.add_argument("--dest", type=Path, required=True)
    parser.add_argument("--name", default="runs/default")
    args = parser.parse_args()
    config, _ = load_policy(args.run / "policy.pt")
    config["logger"]["out"] = args.name
    args.dest.mkdir(parents=True, exist_ok=True)
    copy_policy(args.run / "policy.pt", args.dest / "policy.pt", config)
    write_json(args.dest / "config.json", config)
    shutil.copyfile(args.run / "training.png", args.dest / "training.png")
    if (args.run / MEMBERS_CSV).is_file():  # a run of several seeds: each one's logs in memberK/
        shutil.copyfile(args.run / MEMBERS_CSV, args.dest / MEMBERS_CSV)
        for member in sorted(p for p in args.run.glob("member*") if p.is_dir()):
            recorded = json.loads((member / "config.json").read_text())
            recorded["logger"]["out"] = f"{args.name}/{member.name}"
            (args.dest / member.name).mkdir(exist_ok=True)
            write_json(args.dest / member.name / "config.json", recorded)
            copy_logs(member, args.dest / member.name)
    else:
        copy_logs(args.run, args.dest)


def copy_logs(run: Path, dest: Path) -> None:
    """A run's metrics.csv and, if it was validated, its validation.csv."""
    for name in ("metrics.csv", "validation.csv"):
        if name == "metrics.csv" or (run / name).is_file():
            shutil.copyfile(run / name, dest / name)

if __name__ == "__main__":
    main()
