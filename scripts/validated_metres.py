"""Every kept actor of a run (`nbv train --validation-keep`) scored again as its validation scored it:
coverage (%) and metres flown per episode, on the view lattices or exact renders as the run validated
(issue 26, round 17), or with `--exact` on exact renders whatever the run did.

Written to OUT as JSON: per member folder and actor file, [mean score, metres]. The validation settings
are the run's own (its config.json):

    python scripts/validated_metres.py --run RUN17 --out paper_results/selection/round17/lattice_metres.json
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

from tqdm import tqdm

from common.io import write_json
from common.provenance import config_from_record, git_commit, portable_record
from nbv.rl.checkpoint import load_policy
from nbv.rl.config import TrainConfig
from nbv.rl.validate import Validator, mean_score


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", type=Path, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--exact", action="store_true",
                        help="fly exact renders even if the run validated on the view lattices")
    args = parser.parse_args(argv)
    config = config_from_record(TrainConfig, json.loads((args.run / "config.json").read_text()))
    exact = args.exact or config.validation.validation_exact  # by default as the run's validation flew
    config = replace(config, validation=replace(config.validation, validation_exact=exact))
    validator = Validator(config.env, config.validation, config.network)
    actors = sorted(args.run.glob("**/validated/policy_*.pt"))
    if not actors:
        raise SystemExit(f"no kept actors under {args.run} (train with --validation-keep)")
    scored = {}
    for path in tqdm(actors, unit="actor"):
        scores, metres = validator.score_and_metres(load_policy(path)[1])
        score = mean_score(scores)
        scored[str(path.relative_to(args.run))] = [round(score, 3), round(metres, 3)]
    command = ["scripts/validated_metres.py", *argv]
    fields = [f"{'exact' if exact else 'lattice'} score %", "metres"]
    write_json(args.out, portable_record({"commit": git_commit(), "command": command, "fields": fields,
                                          "actors": scored}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
