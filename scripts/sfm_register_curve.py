"""Registration per view count and resolution, per planner (issue 29): at which count does COLMAP
register a planner's views?

For each planner (default: the shipped policy, the tuned orbit, random views), each view count (default
13, 20, 30, 45) and each resolution (default 320x240, 640x480), the planner chooses its viewpoints on a
training building (`nbv plan`'s `choose_views`, seed 0, the planner's own planning env), they are
rendered at that resolution (spp 16, cached under $NBV_CACHE_DIR/sfm_register_curve) and `nbv sfm` runs
on them (exhaustive matching up to `--spatial-above` views, spatial matching by pose above). A set
registers when at least 90 % of its views are in the largest model, and registers right when that
model's mean camera-centre error after the similarity fit is at most 5 % of the scan radius (a folded
model registers, wrongly). Per planner and resolution the counts run in increasing order and stop at the
first that registers right (`--all-counts`: run them all).
Cases run 13 views first for every planner and resolution, then the larger counts, and the results are
written after every case, so an interrupted run keeps what it measured:

    OUT/register_curve.json  every case's report headline, the command, the commit, the settings
    OUT/register_curve.md    the table, with the smallest count that registers per planner and resolution
    OUT/register_curve.png   registered share against view count, one line per planner and resolution

    nice -n 5 python scripts/sfm_register_curve.py --out paper_results/sfm
    nice -n 5 python scripts/sfm_register_curve.py --out /tmp/c --counts 13 --sizes 160x120 --planners random

With `--min-matches K` the planners that choose among candidates (random, greedy, infogain) fly only
candidates sharing at least K verified matches with a view flown (`nbv plan --min-matches`); their rows
are named `PLANNER --min-matches K`.

    nice -n 5 python scripts/sfm_register_curve.py --out /tmp/l --planners random greedy --counts 13 20 \
        --sizes 320x240 --min-matches 15

Held-out buildings are refused: the curve is a measurement on the buildings the planners were made on.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from common.io import cache_dir, markdown_table, write_json, write_text  # noqa: E402
from common.provenance import git_commit, portable_text  # noqa: E402
from nbv.experiments.planner_study import planner_settings  # noqa: E402
from nbv.planning.config import PlanConfig, PlanSettings  # noqa: E402
from nbv.planning.plan import choose_views, planning_env_config  # noqa: E402
from nbv.planning.registry import make_planner  # noqa: E402
from nbv.sfm.check import sfm_dataset  # noqa: E402
from nbv.sfm.config import LinkSettings, SfmConfig, SfmSettings  # noqa: E402
from render.camera import UAVCamera  # noqa: E402
from render.scan_cache import ensure_scan  # noqa: E402
from render.settings import RenderSettings  # noqa: E402
from scenes.catalog import load_scene  # noqa: E402
from scenes.family_splits import held_out  # noqa: E402
from scenes.spec import SceneSpec  # noqa: E402

SPP = 16
"""Samples per pixel of the SfM renders (as scripts/sfm_measure.py)."""
REGISTERED_SHARE = 0.9
"""A set registers when at least this share of its views is in the largest model (issue 29)."""
RIGHT_PCT_RADIUS = 5.0
"""A registered set's model is right when its mean camera-centre error after the similarity fit is at
most this percentage of the scan radius (a folded model is 50 to 100 %)."""


def parse_size(text: str) -> tuple[int, int]:
    """'WxH' as (W, H)."""
    width, _, height = text.partition("x")
    if not (width.isdigit() and height.isdigit()):
        raise argparse.ArgumentTypeError(f"a size is WIDTHxHEIGHT (e.g. 320x240), got {text!r}")
    return int(width), int(height)


def settings_for(planner: str, min_matches: int) -> PlanSettings:
    """The plan settings of a case: no full scan, `--min-matches` where the planner reads it."""
    linked = PlanSettings(full_scan=False, links=LinkSettings(min_matches=min_matches))
    return planner_settings(linked, planner)


def label(planner: str, min_matches: int) -> str:
    """A case's planner name: the spec, with ` --min-matches K` where the planner flies linked views."""
    k = settings_for(planner, min_matches).links.min_matches
    return f"{planner} --min-matches {k}" if k else planner


def plan_views(scene: str, planner: str, count: int, seed: int, min_matches: int = 0) -> list:
    """The planner's `count` viewpoints on `scene` (seed `seed`), as `nbv plan` chooses them."""
    settings = settings_for(planner, min_matches)
    config = PlanConfig(scene=SceneSpec(scene=scene), views=count, planner=planner, out=Path("unused"),
                        seed=seed, settings=settings)
    made = make_planner(planner, config.settings, seed)
    return choose_views(config, made, planning_env_config(config, made))[0]


def headline(report: dict) -> dict:
    """What the curve keeps of an `nbv sfm` report."""
    pose = report["pose_error"] or {}
    return {"views": report["views"], "registered": report["registered"],
            "registered_share": report["registered_share"], "models": report["models"],
            "reprojection_error_px": report["reprojection_error_px"],
            "centre_error_cm": pose.get("centre_error_cm", {}).get("mean"),
            "centre_error_pct_radius": pose.get("centre_error_pct_radius", {}).get("mean"),
            "relative_rotation_median_deg": pose.get("relative_rotation_error_deg", {}).get("median"),
            "registers": report["registered_share"] >= REGISTERED_SHARE, "seconds": report["seconds"],
            "right": (report["registered_share"] >= REGISTERED_SHARE
                      and pose.get("centre_error_pct_radius", {}).get("mean", math.inf) <= RIGHT_PCT_RADIUS)}


def run_case(args: argparse.Namespace, planner: str, count: int, size: tuple[int, int], views: list) -> dict:
    """Render the views at `size` (cached) and run `nbv sfm` on them; the case's headline."""
    camera = UAVCamera(*size)
    name = f"{planner.replace(':', '_').replace(' --min-matches ', '_links')}-{count}-{size[0]}x{size[1]}"
    folder = cache_dir() / "sfm_register_curve" / f"{args.scene}-{name}"
    ensure_scan(load_scene(args.scene), camera, views, folder, RenderSettings(spp=SPP), progress=False)
    settings = SfmSettings(matching="spatial" if count > args.spatial_above else "exhaustive")
    report = sfm_dataset(SfmConfig(dataset=folder, out=args.work / name, sfm=settings, seed=args.seed,
                                   overwrite=True))
    return {"planner": planner, "count": count, "size": f"{size[0]}x{size[1]}",
            "matching": settings.matching, **headline(report)}


def smallest(cases: list[dict], planner: str, size: str, key: str = "registers") -> int | None:
    """The smallest count at which the planner's views at `size` registered (`key` "right": into a right
    model), None if none did."""
    counts = [c["count"] for c in cases if c["planner"] == planner and c["size"] == size and c[key]]
    return min(counts) if counts else None


def fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else f"{value:{spec}}"


def write_outputs(args: argparse.Namespace, cases: list[dict], command: str, commit: str) -> None:
    """register_curve.{json,md,png} from the cases so far (`commit`: the code's at the start; each case
    records its own, an earlier run's under --resume)."""
    sizes = [f"{w}x{h}" for w, h in args.sizes]
    rows = [[c["planner"], c["size"], str(c["count"]), f"{c['registered']}/{c['views']}", str(c["models"]),
             fmt(c["centre_error_cm"], ".1f"), fmt(c["centre_error_pct_radius"], ".1f"),
             fmt(c["relative_rotation_median_deg"], ".1f"), "yes" if c["registers"] else "no",
             "yes" if c["right"] else "no"] for c in cases]
    found = []
    for planner in (label(p, args.min_matches) for p in args.planners):
        for size in sizes:
            mine = [c["count"] for c in cases if (c["planner"], c["size"]) == (planner, size)]
            if mine:
                least = [smallest(cases, planner, size, key) for key in ("registers", "right")]
                none = f"none up to {max(mine)}"
                found.append([planner, size, *(none if n is None else str(n) for n in least)])
    text = "\n".join([
        f"# Registration per view count and resolution: {args.scene} (commit {commit})", "",
        f"`{command}`", "",
        f"COLMAP (pycolmap, CPU, intrinsics fixed, seed {args.seed}) on each planner's views, rendered at "
        f"spp {SPP}; exhaustive matching up to {args.spatial_above} views, spatial above. 'registers': at "
        f"least {REGISTERED_SHARE:.0%} of the views in the largest model. Centre error: the largest model's "
        "mean after a similarity fit; relative rotation: median over pairs (large: the model folds). "
        f"'right': registers with a mean centre error of at most {RIGHT_PCT_RADIUS:g} % of the scan radius.",
        "",
        markdown_table(["planner", "size", "views", "registered", "models", "centre cm", "centre % R",
                        "rel. rotation deg", "registers", "right"], rows), "",
        "## Smallest count that registers", "",
        markdown_table(["planner", "size", "registers", "registers right"], found), ""])
    write_text(args.out / "register_curve.md", text)
    write_json(args.out / "register_curve.json", {"commit": commit, "command": command,
                                                  "scene": args.scene, "seed": args.seed, "spp": SPP,
                                                  "registered_share": REGISTERED_SHARE, "cases": cases})
    plot(cases, args.out / "register_curve.png", args.scene)


def plot(cases: list[dict], path: Path, scene: str) -> None:
    """Registered share against view count, one line per planner and size."""
    fig, ax = plt.subplots(figsize=(6, 4))
    for key in dict.fromkeys((c["planner"], c["size"]) for c in cases):
        mine = sorted((c["count"], c["registered_share"], c["right"]) for c in cases
                      if (c["planner"], c["size"]) == key)
        line, = ax.plot([m[0] for m in mine], [m[1] for m in mine], label=f"{key[0]} {key[1]}")
        for count, share, right in mine:  # hollow: no model, or a wrong (folded) one
            ax.plot(count, share, "o", color=line.get_color(), fillstyle="full" if right else "none")
    ax.axhline(REGISTERED_SHARE, color="grey", linestyle=":", linewidth=1)
    ax.set(xlabel="views", ylabel="share registered (largest model)", ylim=(-0.05, 1.05),
           title=f"COLMAP registration: {scene} (filled: a right model)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str]) -> int:
    """Plan, render and reconstruct each case in order, writing the outputs after each."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="medieval_tavern")
    parser.add_argument("--planners", nargs="+", default=["policy", "orbit", "random"])
    parser.add_argument("--counts", nargs="+", type=int, default=[13, 20, 30, 45])
    parser.add_argument("--sizes", nargs="+", type=parse_size, default=[(320, 240), (640, 480)])
    parser.add_argument("--spatial-above", type=int, default=30, help="spatial matching above this count")
    parser.add_argument("--all-counts", action="store_true", help="do not stop at the first that registers")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--min-matches", type=int, default=0,
                        help="random, greedy and infogain fly only views linked by K verified matches")
    parser.add_argument("--resume", action="store_true",
                        help="reuse OUT/register_curve.json's cases (measured at the commit each records)")
    parser.add_argument("--report-only", action="store_true",
                        help="rewrite OUT/register_curve.{md,png} from its .json, running nothing")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--work", type=Path, default=None, help="nbv sfm outputs (default OUT/runs)")
    args = parser.parse_args(argv)
    if held_out(args.scene):
        parser.error(f"{args.scene} is a held-out building; run the curve on a training building")
    args.work = args.work or args.out / "runs"
    args.out.mkdir(parents=True, exist_ok=True)
    if args.report_only:
        doc = json.loads((args.out / "register_curve.json").read_text())
        write_outputs(args, doc["cases"], doc["command"], doc["commit"])
        return 0
    command = portable_text("python scripts/sfm_register_curve.py " + " ".join(argv))  # no machine paths
    commit = git_commit()
    for planner in args.planners:  # each factory imported now, as at `commit`
        make_planner(planner, PlanSettings(full_scan=False), args.seed)
    done = previous(args.out / "register_curve.json") if args.resume else {}
    cases: list[dict] = []
    views: dict[tuple[str, int], list] = {}
    for count in sorted(args.counts):
        for spec in args.planners:
            planner = label(spec, args.min_matches)
            for size in args.sizes:
                if not args.all_counts and smallest(cases, planner, f"{size[0]}x{size[1]}", "right"):
                    continue
                start, key = time.perf_counter(), (planner, count, f"{size[0]}x{size[1]}")
                if key in done:
                    cases.append(done[key])
                    continue
                if (planner, count) not in views:
                    views[(planner, count)] = plan_views(args.scene, spec, count, args.seed, args.min_matches)
                found = run_case(args, planner, count, size, views[(planner, count)])
                cases.append({**found, "commit": commit})
                c = cases[-1]
                print(f"{planner} {c['size']} {count}: {c['registered']}/{c['views']} in {c['models']} "
                      f"model(s), centre {fmt(c['centre_error_cm'], '.1f')} cm "
                      f"({time.perf_counter() - start:.0f} s)", flush=True)
                write_outputs(args, cases, command, commit)
    write_outputs(args, cases, command, commit)  # the cases reused from --resume after the last one run
    return 0


def previous(path: Path) -> dict[tuple[str, int, str], dict]:
    """The cases of an earlier run's register_curve.json by (planner, count, size) ({} if none)."""
    if not path.is_file():
        return {}
    doc = json.loads(path.read_text())
    return {(c["planner"], c["count"], c["size"]): {"commit": doc["commit"], **c} for c in doc["cases"]}


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
