"""Compare planners on one (held-out) scene over seeds: views, coverage, Chamfer, Hausdorff.

Thin over `nbv.plan.compare_planners`; every `nbv plan` option applies to all runs.

    .venv/bin/python scripts/compare_planners.py alpine_chalet --views 13 \\
        --planners policy:runs/policy/checkpoint.pt random circle greedy --seeds 0 1 2 --out cmp
"""

from __future__ import annotations

import argparse
from pathlib import Path

from nbv.cli.config_args import add_config_arguments, config_from_args
from nbv.plan import PlanConfig, compare_planners


def main() -> None:
    """Parse the options, run every planner and seed, print the table."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    add_config_arguments(parser, PlanConfig)
    parser.add_argument("--planners", nargs="+", default=["random", "circle", "greedy"],
                        help="planners to compare (policy:CHECKPOINT, policy-sample:CHECKPOINT, random, "
                             "circle, greedy, hemisphere)")
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2], help="seeds per planner")
    args = parser.parse_args()
    base = config_from_args(PlanConfig, args)
    print(compare_planners(base, args.planners, args.seeds, Path(args.out)))


if __name__ == "__main__":
    main()
