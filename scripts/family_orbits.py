"""No single orbit is best across the trait family (issue 26): coverage per building per ring.

Every ring of `--rings` (orbit:R,E specs) is flown at `--views` views on each of `--scenes` (training or
validation `family:SEED` buildings of different traits; a held-out building is refused), each run an
`nbv plan` run of a `PlannerStudy` scored by the project's measure: the TSDF reconstruction's coverage
of the true surface. A table of coverage per building per ring, each building's best ring marked, goes
to `--out`/orbits.md (with the commit and the command) and the scores to `--out`/orbits.json. Runs
already in `--runs` are read back, so an interrupted table resumes.

    nice -n 5 python scripts/family_orbits.py --runs runs/family_orbits --out paper_results/family
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from common.io import markdown_table, write_json, write_text
from common.provenance import git_commit
from nbv.experiments.planner_study import PlannerStudy, run_study
from nbv.planning.config import PlanSettings
from nbv.recon.config import MetricsConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.family_splits import family_trait, held_out, parse_family

SCENES = ("family:1", "family:2", "family:3", "family:6", "family:7", "family:8")
"""Training buildings, one per seen trait: tower, courtyard, U plan, L plan, arcade, hall."""
RINGS = ("orbit:1.5,5", "orbit:1.5,25", "orbit:2,45", "orbit:1.75,15")
"""The rings compared: low and close, the shipped 25 degrees, high and far, between."""


def score(args: argparse.Namespace, scene: str, ring: str) -> float:
    """Coverage (%) of the true surface of `ring` on `scene` (mean over seeds)."""
    settings = PlanSettings(camera=UAVCamera(width=args.width, height=args.height),
                            render=RenderSettings(spp=args.spp), full_scan=False,
                            metrics=MetricsConfig(n_points=args.metric_points))
    study = PlannerStudy(scenes=(scene,), planners=(ring,), seeds=tuple(args.seeds), budgets=(args.views,),
                         settings=settings, out=args.runs, runs="{scene}/{planner}-v{views}-seed{seed}")
    return 100 * float(np.mean([run.plan()["gt"]["coverage"] for run in run_study(study)]))


def report(args: argparse.Namespace, scores: dict[str, dict[str, float]], commit: str) -> str:
    """Markdown: one row per building, its coverage per ring, its best ring in bold."""
    rows = []
    for scene, per in scores.items():
        best = max(per, key=per.get)
        rows.append([f"`{scene}` ({family_trait(parse_family(scene))})",
                     *(f"**{per[r]:.1f}**" if r == best else f"{per[r]:.1f}" if r in per else "-"
                       for r in args.rings)])
    bests = {max(per, key=per.get) for per in scores.values() if per}
    return "\n\n".join([
        f"Coverage (%) of the true surface, {args.views} views, {args.width}x{args.height}, spp {args.spp}, "
        f"seeds {', '.join(map(str, args.seeds))}, commit {commit}. Best rings: {', '.join(sorted(bests))}. "
        f"Re-run: `nice -n 5 python {' '.join(sys.argv)}`",
        markdown_table(["building", *(f"`{r}`" for r in args.rings)], rows)]) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, default=Path("runs/family_orbits"), help="the plan runs' folder")
    parser.add_argument("--out", type=Path, default=Path("paper_results/family"), help="table and scores")
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), help="training/validation family:SEED")
    parser.add_argument("--rings", nargs="+", default=list(RINGS), help="orbit:R,E specs")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--views", type=int, default=13)
    parser.add_argument("--width", type=int, default=128)
    parser.add_argument("--height", type=int, default=96)
    parser.add_argument("--spp", type=int, default=1)
    parser.add_argument("--metric-points", type=int, default=100_000)
    args = parser.parse_args()
    for scene in args.scenes:
        parse_family(scene)
        if held_out(scene):
            raise SystemExit(f"{scene} is a held-out building; compare rings on training/validation ones")
    args.out.mkdir(parents=True, exist_ok=True)
    commit, scores = git_commit(), {}
    for scene in args.scenes:  # the table is rewritten after every run, so a partial one is kept
        scores[scene] = {}
        for ring in args.rings:
            start = time.perf_counter()
            scores[scene][ring] = score(args, scene, ring)
            print(f"{ring} on {scene}: {scores[scene][ring]:.1f} % ({time.perf_counter() - start:.0f} s)",
                  flush=True)
            write_json(args.out / "orbits.json", {"commit": commit, "command": " ".join(sys.argv),
                                                  "scores": scores})
            write_text(args.out / "orbits.md", report(args, scores, commit))


if __name__ == "__main__":
    sys.exit(main())
