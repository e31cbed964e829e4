"""Check that the oracle is at least every budget planner on `nbv plan`'s coverage (issue 26's acceptance).

Every planner the oracle bounds (`nbv.planning.oracle.baseline_names`) and the oracle itself are planned,
captured, fused and scored by `nbv plan`'s own pipeline (`plan_scan`, ground truth only) at each budget
and seed; the table gives each one's coverage of the true surface (%) and which set the oracle returned
(`own`: its greedy pick; else the planner whose views it took). Exits 1 if the oracle is below any.

    PYTHONPATH=. python scripts/oracle_bound.py --scene test_building --width 160 --height 120 \\
        --views 3 5 --seeds 0 1 --out /tmp/oracle_bound
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.oracle import baseline_names
from nbv.planning.plan import plan_scan
from nbv.recon.config import MetricsConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.spec import SceneSpec


def bound_rows(scene: str, settings: PlanSettings, views: list[int], seeds: list[int],
               out: Path) -> list[dict]:
    """Per budget and seed: every planner's coverage of the true surface and the set the oracle returned."""
    rows = []
    for count in views:
        for seed in seeds:
            plans = {planner: plan_scan(PlanConfig(scene=SceneSpec(scene=scene), views=count, planner=planner,
                                                   seed=seed, out=out / f"{planner}-v{count}-seed{seed}",
                                                   overwrite=True, settings=settings))
                     for planner in (*baseline_names(), "oracle")}
            taken = [p for p in baseline_names() if plans[p]["viewpoints"] == plans["oracle"]["viewpoints"]]
            rows.append({"views": count, "seed": seed, "taken": taken[0] if taken else "own",
                         "coverage": {p: doc["gt"]["coverage"] for p, doc in plans.items()}})
    return rows


def bounded(rows: list[dict]) -> bool:
    """Whether the oracle is at least every planner in every row."""
    return all(row["coverage"]["oracle"] >= max(row["coverage"].values()) for row in rows)


def main() -> int:
    """Run the check; print the table; 1 if the oracle falls below a planner anywhere."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", default="test_building")
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=120)
    parser.add_argument("--spp", type=int, default=1)
    parser.add_argument("--metric-points", type=int, default=20_000)
    parser.add_argument("--views", type=int, nargs="+", default=[3, 5])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--out", type=Path, default=Path("/tmp/oracle_bound"))
    args = parser.parse_args()
    settings = PlanSettings(camera=UAVCamera(args.width, args.height), render=RenderSettings(spp=args.spp),
                            full_scan=False, metrics=MetricsConfig(n_points=args.metric_points))
    rows = bound_rows(args.scene, settings, args.views, args.seeds, args.out)
    planners = list(rows[0]["coverage"])
    print(f"{args.scene}, {args.width}x{args.height}, spp {args.spp}, {args.metric_points} metric points")
    print("| views | seed | " + " | ".join(planners) + " | oracle took |")
    print("|---" * (len(planners) + 3) + "|")
    for row in rows:
        cells = " | ".join(f"{100 * row['coverage'][p]:.2f}" for p in planners)
        print(f"| {row['views']} | {row['seed']} | {cells} | {row['taken']} |")
    return 0 if bounded(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
