"""Copy a finished `nbv train` run into the package as the shipped policy (issue 11).

Writes DEST/policy.pt (the actor and config, `weights_only`-loadable), config.json, metrics.csv,
training.png and, for a validated run, validation.csv. The run's output folder in the recorded config
is replaced by `--name` (a relative path), so no machine path is committed; nothing else changes.

    python scripts/ship_policy.py --run runs/default --dest nbv/planning/shipped --name runs/default
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

from common.io import write_json
from nbv.rl.checkpoint import POLICY_FORMAT, checkpoint_config, load_checkpoint, save_policy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", type=Path, required=True)
    parser.add_argument("--dest", type=Path, required=True)
    parser.add_argument("--name", default="runs/default")
    args = parser.parse_args()
    state = load_checkpoint(args.run / "policy.pt", (POLICY_FORMAT,))
    config = checkpoint_config(state, args.run / "policy.pt")
    config["logger"]["out"] = args.name
    args.dest.mkdir(parents=True, exist_ok=True)
    save_policy(args.dest / "policy.pt", json.dumps(config),
                {f"actor_network_params.{k}": v for k, v in state["actor"].items()}, state["counters"])
    write_json(args.dest / "config.json", config)
    optional = [] if not (args.run / "validation.csv").is_file() else ["validation.csv"]
    for name in ("metrics.csv", "training.png", *optional):
        shutil.copyfile(args.run / name, args.dest / name)


if __name__ == "__main__":
    main()
