"""How well plane-sweep stereo measures a building's depth from two frames (round 25; training buildings).

`lookahead-stereo` (`nbv.planning.lookahead`) fuses the depth that plane-sweep stereo (`nbv.recon.stereo`)
finds between each view and a second frame a short step along its orbit. This study chooses that step (the
baseline, metres) and the sweep's settings: on training buildings, from random views of the default preset's
ranges and camera (160 x 120, its render settings), each setting's depth of the view is compared with the
renderer's exact depth on the pixels whose surface lies inside the target's box (what the look-ahead's grid
holds):

- measured: the share of those pixels that keep a depth;
- median error: of the kept depths, relative to the exact one;
- wrong: the share of kept depths more than 5 % off (they mark the wrong voxel occupied).

`stereo.png` shows the first building's first view at the first baseline: its frame, the exact depth, the
chosen setting's stereo depth and its error.

The rule, set before the run: the setting and baseline that measure the most pixels with at most 5 % of
them wrong.

    python scripts/stereo_depth_eval.py --baselines 0.15 0.25 0.4 --out OUT

With `--partners`, each view is also swept with second frames on other sides (`back,up`: one back along
the orbit, one up the meridian, each swept with the view; a pixel counts as measured if any pair measures
it, and every pair's kept depths count towards the errors, as the grid fuses each); `back,forward,up@2`
keeps only the depth that at least two pairs agree on (`nbv.recon.stereo.agreed_depth`; round 26).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from tqdm import tqdm

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import git_commit, portable_record
from nbv.planning.lookahead import PARTNER_SIDES, STEREO_BASELINE_M, stereo_partner
from nbv.planning.world import PlanningWorld
from nbv.recon.stereo import StereoConfig, agreed_depth, box_stereo_depth, grayscale
from nbv.rl.presets import TRAIN_SCENES, default_preset
from nbv.rl.validate import evaluation_env_config
from nbv.viz.figures import save_figure
from render.camera import pixel_rays
from render.viewpoint import draw_viewpoint, viewpoint_to_c2w
from scenes.family_splits import held_out
from scenes.spec import SceneSet

VARIANTS = {"round 25's start": {"window": 7, "min_correlation": 0.7}, "window 9": {"min_correlation": 0.7},
            "window 5": {"window": 5, "min_correlation": 0.7}, "ncc 0.6": {"window": 7},
            "ncc 0.8": {"window": 7, "min_correlation": 0.8},
            "consistency 0.01": {"window": 7, "min_correlation": 0.7, "consistency": 0.01},
            "192 hypotheses": {"window": 7, "min_correlation": 0.7, "hypotheses": 192},
            "window 9, ncc 0.6": {}}
"""The sweep settings tried, as changes to `StereoConfig`'s defaults (round 25 started at a window of 7 and a
least correlation of 0.7, and chose the last)."""


def score_view(world: PlanningWorld, view, baseline: float, configs: dict[str, StereoConfig],
               figure: Path | None = None, sides: tuple[str, ...] = ("back",), agree: int = 0) -> dict:
    """Each setting's (target pixels, kept, errors) on one view swept with its second frame on each of
    `sides` (kept: measured by any pair; errors: every pair's kept depths, as the grid fuses each; with
    `agree` >= 1, the one depth that many pairs agree on, `agreed_depth`); with `figure`, the view's picture
    of the default setting written there."""
    target, camera = world.target, world.camera
    lower, upper = target.bounds()
    pose = viewpoint_to_c2w(view, target.center())
    image = grayscale(world.source.render_rgb(view))
    seconds = [stereo_partner(view, baseline, side) for side in sides]
    others = [viewpoint_to_c2w(second, target.center()) for second in seconds]
    partners = [grayscale(world.source.render_rgb(second)) for second in seconds]
    exact = world.source.render_depth(view)
    rays = pixel_rays(camera.K, camera.width, camera.height)
    points = (rays * exact[..., None]) @ pose[:3, :3].T + pose[:3, 3]
    inside = (exact > 0) & np.all((points >= lower - 1e-3) & (points <= upper + 1e-3), axis=-1)
    scores = {}
    for name, config in configs.items():
        depths = [box_stereo_depth(image, partner, camera.K, pose, other, lower, upper, config)[0]
                  for other, partner in zip(others, partners, strict=True)]
        if agree:
            depths = [agreed_depth(depths, config.consistency, agree)]
        kept, errors = np.zeros_like(inside), []
        for depth in depths:
            pair = np.isfinite(depth) & inside
            kept |= pair
            errors.extend((np.abs(depth[pair] - exact[pair]) / exact[pair]).tolist())
        scores[name] = (int(inside.sum()), int(kept.sum()), errors)
        if figure is not None and config == StereoConfig():
            depth_figure(image, exact, depth, inside, figure)
    return scores


def depth_figure(image: np.ndarray, exact: np.ndarray, stereo: np.ndarray, inside: np.ndarray,
                 out: Path) -> Path:
    """The frame, its exact depth, the stereo depth (blank where not measured) and the relative error."""
    fig = Figure(figsize=(12, 2.9))
    shown = np.where(exact > 0, exact, np.nan)
    low, high = np.nanmin(shown), np.nanmax(shown)
    error = np.abs(stereo - exact) / np.where(exact > 0, exact, np.nan)
    panels = [(image, "frame", "gray", (0, 1)), (shown, "exact depth (m)", "viridis", (low, high)),
              (stereo, f"stereo depth: {100 * np.isfinite(stereo[inside]).mean():.0f} % of the target",
               "viridis", (low, high)), (error, "relative error (0 to 10 %)", "magma", (0, 0.1))]
    for index, (data, title, cmap, (vmin, vmax)) in enumerate(panels):
        ax = fig.add_subplot(1, 4, index + 1)
        shown_image = ax.imshow(data, cmap=cmap, vmin=vmin, vmax=vmax)
        ax.set_title(title, fontsize=9)
        ax.set_axis_off()
        if index:
            fig.colorbar(shown_image, ax=ax, fraction=0.035)
    return save_figure(fig, out)


def measure(scenes: list[str], baselines: list[float], views: int, configs: dict[str, StereoConfig],
            figure: Path, partners: list[str]) -> dict[tuple[str, float, str], list]:
    """Per (partner sides, baseline, setting): target pixels, kept pixels and the kept depths' relative
    errors, summed over `views` random views of each building (the picture of the first building's first
    view at the shipped baseline, or the first, with the first partners, written to `figure`); a set of
    partners is sides, comma-joined, and @N to keep only depths N pairs agree on (`partner_set`)."""
    trained = default_preset().env
    shown = STEREO_BASELINE_M if STEREO_BASELINE_M in baselines else baselines[0]
    totals: dict[tuple[str, float, str], list] = {
        (spec, b, n): [0, 0, []] for spec in partners for b in baselines for n in configs}
    for scene in tqdm(scenes, desc="buildings", unit="building"):
        world = PlanningWorld(evaluation_env_config(trained, SceneSet(scene=(scene,))), seed=0)
        rng = np.random.default_rng(0)
        drawn = [draw_viewpoint(trained.low, trained.high, rng) for _ in range(views)]
        for view in drawn:
            for spec in partners:
                for baseline in baselines:
                    first = (scene, view, baseline, spec) == (scenes[0], drawn[0], shown, partners[0])
                    scores = score_view(world, view, baseline, configs, figure if first else None,
                                        *partner_set(spec))
                    for name, (inside, kept, error) in scores.items():
                        total = totals[spec, baseline, name]
                        total[0], total[1] = total[0] + inside, total[1] + kept
                        total[2].extend(error)
    return totals


def partner_set(spec: str) -> tuple[tuple[str, ...], int]:
    """`back,up` -> the sides and 0 (every pair's depth kept); `back,forward,up@2` -> the sides and 2 (only
    depths two pairs agree on)."""
    sides, _, agree = spec.partition("@")
    parts = tuple(sides.split(","))
    if not set(parts) <= set(PARTNER_SIDES) or not (agree == "" or agree.isdigit()):
        raise ValueError(f"--partners takes comma-joined sides from {PARTNER_SIDES}, then @N or nothing, "
                         f"got {spec!r}")
    return parts, int(agree or 0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=list(TRAIN_SCENES[:4]))
    parser.add_argument("--baselines", type=float, nargs="+", default=[0.15, 0.25, 0.4])
    parser.add_argument("--views", type=int, default=8, help="random views per building")
    parser.add_argument("--partners", nargs="+", default=["back"],
                        help=f"sets of second frames' sides, comma-joined, from {PARTNER_SIDES}")
    parser.add_argument("--settings", nargs="+", choices=list(VARIANTS), default=list(VARIANTS),
                        help="the sweep settings to score")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    if any(held_out(s) for s in args.scenes):
        raise SystemExit("held-out buildings are not for choosing: give training ones")
    try:
        [partner_set(spec) for spec in args.partners]
    except ValueError as error:
        raise SystemExit(str(error)) from None
    configs = {name: replace(StereoConfig(), **VARIANTS[name]) for name in args.settings}
    with atomic_folder(args.out, overwrite=True, outputs=("results.json", "results.md", "stereo.png")) as out:
        totals = measure(args.scenes, args.baselines, args.views, configs, out / "stereo.png", args.partners)
        rows, records = [], []
        for (sides, baseline, name), (inside, kept, error) in totals.items():
            record = {"partners": sides, "baseline_m": baseline, "setting": name,
                      "measured": kept / max(inside, 1),
                      "median_error": float(np.median(error)) if error else None,
                      "wrong": float(np.mean(np.array(error) > 0.05)) if error else None}
            records.append(record)
            rows.append([sides, f"{baseline:g}", name, f"{100 * record['measured']:.1f}",
                         "-" if not error else f"{100 * record['median_error']:.2f}",
                         "-" if not error else f"{100 * record['wrong']:.1f}"])
        table = markdown_table(["partners", "baseline (m)", "setting", "measured %", "median error %",
                                "wrong (> 5 %) %"], rows)
        command = portable_record({k: str(v) for k, v in vars(args).items()})
        write_json(out / "results.json", {"command": command, "commit": git_commit(), "results": records})
        write_text(out / "results.md", f"# Plane-sweep stereo depth on training buildings\n\n{table}\n\n"
                   "![one view](stereo.png)\n")
    print(table)


if __name__ == "__main__":
    main()
