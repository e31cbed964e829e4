"""Choose the `orbit` and `orbit2` rings on the training buildings (issue 26): the recorded command.

Every ring of a grid (radii x elevations, inside the allowed ranges) is flown as `orbit:R,E` at `--views`
views on every training building (`nbv.rl.presets.TRAIN_SCENES`; a test building, alpine_chalet,
imperial_temple, random:SEED with SEED % 5 == 0 or a held-out family:SEED, is refused), each run an
`nbv plan` run of a `PlannerStudy` scored by the project's measure: the TSDF reconstruction's coverage of
the true surface. The ring of the best mean is `orbit`. Then every two-ring pattern whose first ring is
one of the `--first` best single rings or a ring of the `--pair-radii` (default: the grid's) at a
`--first-elevations` elevation, and whose second is a ring of the `--pair-radii` at a
`--second-elevations` elevation above the first's, is flown as `orbit2:R1,E1,R2,E2`; the best mean
is `orbit2`. The choice, the command, the commit, the resolution and
every score go to `--out` (the shipped `nbv/planning/shipped/orbit.json`, read by the planners), a table
to `--table`. Runs already in `--runs` are read back, so an interrupted choice resumes.

    nice -n 5 python scripts/choose_orbit.py --runs runs/choose_orbit
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
from pathlib import Path

import numpy as np

from common.io import markdown_table, write_json, write_text
from common.provenance import git_commit
from nbv.experiments.planner_study import PlannerStudy, run_study
from nbv.planning.config import PlanSettings
from nbv.planning.orbit import SHIPPED_ORBIT
from nbv.recon.config import MetricsConfig
from nbv.rl.presets import TRAIN_SCENES
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.family_splits import held_out


def check_training(scenes: list[str]) -> None:
    """Refuse any test building: the rings are chosen on training buildings only."""
    for scene in scenes:
        if held_out(scene):
            raise SystemExit(f"{scene} is a held-out test building; choose the rings on training buildings")


def spec(name: str, rings: tuple[tuple[float, float], ...]) -> str:
    """The planner spec of `rings`: orbit:R,E or orbit2:R1,E1,R2,E2."""
    return f"{name}:" + ",".join(f"{radius:g},{elevation:g}" for radius, elevation in rings)


def score(args: argparse.Namespace, settings: PlanSettings, planner: str) -> dict[str, float]:
    """Coverage (%) of the true surface per training building (mean over seeds) of one planner spec."""
    scores = {}
    for scene in args.scenes:  # one study per building: progress as each finishes, resumable
        study = PlannerStudy(scenes=(scene,), planners=(planner,), seeds=tuple(args.seeds),
                             budgets=(args.views,), settings=settings, out=args.runs,
                             runs="{scene}/{planner}-v{views}-seed{seed}")
        start = time.perf_counter()
        runs = run_study(study)
        scores[scene] = 100 * float(np.mean([run.plan()["gt"]["coverage"] for run in runs]))
        seconds = time.perf_counter() - start
        print(f"{planner} on {scene}: {scores[scene]:.1f} % ({seconds:.0f} s)", flush=True)
    return scores


def table(scores: dict[str, dict[str, float]], scenes: list[str]) -> str:
    """Markdown: one row per spec, best mean first, its coverage per building and the mean."""
    rows = [[f"`{name}`", *(f"{per[s]:.1f}" for s in scenes), f"**{np.mean(list(per.values())):.1f}**"]
            for name, per in sorted(scores.items(), key=lambda kv: -np.mean(list(kv[1].values())))]
    return markdown_table(["rings", *scenes, "mean"], rows)


def choose(args: argparse.Namespace) -> dict:
    """Score the grid, then the two-ring patterns; return the shipped document."""
    settings = PlanSettings(camera=UAVCamera(width=args.width, height=args.height),
                            render=RenderSettings(spp=args.spp), full_scan=False,
                            metrics=MetricsConfig(n_points=args.metric_points))
    commit = git_commit()
    grid = list(itertools.product(args.radii, args.elevations))
    single = {spec("orbit", (ring,)): score(args, settings, spec("orbit", (ring,))) for ring in grid}
    ranked = sorted(grid, key=lambda ring: -np.mean(list(single[spec("orbit", (ring,))].values())))
    radii = args.pair_radii or args.radii
    firsts = dict.fromkeys([*ranked[:args.first], *itertools.product(radii, args.first_elevations)])
    seconds = list(itertools.product(radii, args.second_elevations))
    pairs = [(first, second) for first in firsts for second in seconds if second[1] > first[1]]
    double = {spec("orbit2", pair): score(args, settings, spec("orbit2", pair)) for pair in pairs}
    best2 = max(pairs, key=lambda pair: np.mean(list(double[spec("orbit2", pair)].values())))
    command = "nice -n 5 python " + " ".join(sys.argv)
    return {"rings": {"orbit": [list(ranked[0])], "orbit2": [list(ring) for ring in best2]},
            "command": command, "commit": commit, "scenes": args.scenes, "seeds": args.seeds,
            "views": args.views, "measure": "coverage (%) of the true surface by the TSDF reconstruction, "
            f"within {settings.metrics.threshold_cm:g} cm, on {args.metric_points} samples",
            "resolution": {"width": args.width, "height": args.height, "spp": args.spp},
            "scores": {"orbit": single, "orbit2": double}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, default=Path("runs/choose_orbit"), help="the plan runs' folder")
    parser.add_argument("--out", type=Path, default=SHIPPED_ORBIT, help="the choice (JSON)")
    parser.add_argument("--table", type=Path, default=SHIPPED_ORBIT.with_suffix(".md"), help="the scores")
    parser.add_argument("--scenes", nargs="+", default=list(TRAIN_SCENES), help="training buildings")
    parser.add_argument("--radii", type=float, nargs="+", default=[1.5, 2.0, 2.5], help="metres")
    parser.add_argument("--elevations", type=float, nargs="+", default=[5, 15, 25, 35], help="degrees")
    parser.add_argument("--second-elevations", type=float, nargs="+", default=[25, 40],
                        help="degrees of orbit2's second ring")
    parser.add_argument("--first", type=int, default=1, help="best single rings tried as orbit2's first")
    parser.add_argument("--first-elevations", type=float, nargs="+", default=[],
                        help="degrees of orbit2's other first rings")
    parser.add_argument("--pair-radii", type=float, nargs="+",
                        help="metres of orbit2's rings (default: --radii)")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--views", type=int, default=13)
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=120)
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--metric-points", type=int, default=200_000)
    args = parser.parse_args()
    check_training(args.scenes)
    doc = choose(args)
    write_json(args.out, doc)
    scenes = args.scenes
    write_text(args.table, "\n\n".join([
        f"Coverage (%) of the true surface, {args.views} views, {args.width}x{args.height}, spp {args.spp}, "
        f"seeds {', '.join(map(str, args.seeds))}, commit {doc['commit']}; chosen: orbit "
        f"{doc['rings']['orbit']}, orbit2 {doc['rings']['orbit2']}. Re-run: `{doc['command']}`",
        "## One ring", table(doc["scores"]["orbit"], scenes),
        "## Two rings", table(doc["scores"]["orbit2"], scenes)]) + "\n")
    print(f"orbit {doc['rings']['orbit']}, orbit2 {doc['rings']['orbit2']} -> {args.out}")


if __name__ == "__main__":
    sys.exit(main())
