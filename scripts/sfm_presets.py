"""Issue 29's acceptance: `nbv sfm` on each preset's full 288-view hemisphere scan, as a table and figures.

For every scene: `nbv scan SCENE hemisphere --out RUNS/NAME-scan` (default camera 320x240, spp 16) and
`nbv sfm RUNS/NAME-scan --out RUNS/NAME-sfm --matching spatial`, each skipped where its output is
already there (`--reuse`). Then it writes OUT/presets.json and OUT/presets.md (registered share, models,
points, reprojection error, centre and rotation errors after the similarity fit), OUT/presets_centres.png
(the true camera centres and the fitted model's, seen from above) and OUT/presets_look.jpg (one render
of each preset).

    nice -n 5 python scripts/sfm_presets.py --runs sfm_runs --out paper_results/sfm
    nice -n 5 python scripts/sfm_presets.py --runs sfm_runs --out OUT --scenes medieval_tavern@tiled
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

from common.io import markdown_table
from nbv.sfm.align import umeyama
from nbv.sfm.report import model_poses
from render.dataset import read_dataset

PRESETS = ("medieval_tavern", "forest_ruin_house", "alpine_chalet", "imperial_temple")
"""The scenes of the acceptance."""
SHARE_MIN, CENTRE_MAX_PCT = 0.98, 1.0
"""The acceptance: at least 98 % of the views in one model, mean centre error at most 1 % of the radius."""


def folder_name(scene: str) -> str:
    """A scene name as a folder name."""
    return scene.replace(":", "_").replace("@", "_")


def outputs(scene: str, runs: Path) -> tuple[Path, Path]:
    """The scan and SfM folders of one scene."""
    return runs / f"{folder_name(scene)}-scan", runs / f"{folder_name(scene)}-sfm"


def commands(scene: str, runs: Path) -> list[list[str]]:
    """The two `nbv` command lines of one scene."""
    scan, sfm = outputs(scene, runs)
    return [["nbv", "scan", scene, "hemisphere", "--out", str(scan), "--overwrite"],
            ["nbv", "sfm", str(scan), "--out", str(sfm), "--matching", "spatial", "--overwrite"]]


def run_scene(scene: str, runs: Path, reuse: bool) -> dict:
    """Scan and reconstruct `scene` (each step skipped with `reuse` where its output exists); its sfm.json."""
    scan, sfm = outputs(scene, runs)
    for command, done in zip(commands(scene, runs), (scan / "transforms.json", sfm / "sfm.json")):
        if not (reuse and done.exists()):
            subprocess.run([sys.executable, "-m", "nbv.cli", *command[1:]], check=True)
    return json.loads((sfm / "sfm.json").read_text())


def row(scene: str, report: dict) -> dict:
    """The headline of one scene's report, with the acceptance verdict."""
    error = report["pose_error"] or {}
    centre, pct = error.get("centre_error_cm", {}), error.get("centre_error_pct_radius", {})
    passed = report["registered_share"] >= SHARE_MIN and pct.get("mean", math.inf) <= CENTRE_MAX_PCT
    return {"scene": scene, "views": report["views"], "registered": report["registered"],
            "registered_share": report["registered_share"], "models": report["models"],
            "points": report["points"], "reprojection_error_px": report["reprojection_error_px"],
            "centre_error_cm": centre, "centre_error_pct_radius": pct,
            "rotation_error_deg": error.get("rotation_error_deg"),
            "relative_rotation_error_deg": error.get("relative_rotation_error_deg"),
            "seconds": report.get("seconds"), "accepted": passed}


def markdown(rows: list[dict]) -> str:
    """The table of presets.md."""
    def cell(value, fmt):
        return "-" if value is None else fmt.format(value)

    body = [[r["scene"], f"{r['registered']} / {r['views']} ({100 * r['registered_share']:.1f} %)",
             str(r["models"]), str(r["points"]), cell(r["reprojection_error_px"], "{:.2f}"),
             cell(r["centre_error_cm"].get("mean"), "{:.2f}"),
             cell(r["centre_error_cm"].get("max"), "{:.2f}"),
             cell(r["centre_error_pct_radius"].get("mean"), "{:.2f}"),
             cell((r["rotation_error_deg"] or {}).get("mean"), "{:.2f}"),
             cell((r["relative_rotation_error_deg"] or {}).get("median"), "{:.2f}"),
             "yes" if r["accepted"] else "no"] for r in rows]
    return markdown_table(["scene", "registered", "models", "points", "reproj. px", "centre mean cm",
                           "centre max cm", "centre mean % R", "rotation mean deg",
                           "rel. rotation median deg", "accepted"], body)


def fitted_centres(scan: Path, sfm: Path) -> tuple[np.ndarray, np.ndarray]:
    """True camera centres of the registered views and the largest model's, carried by the similarity fit."""
    import pycolmap

    dataset = read_dataset(scan)
    truth = {f.rgb_path.name: f.c2w for f in dataset.frames}
    poses = model_poses(pycolmap.Reconstruction(str(sfm / "sparse" / "0")))
    names = sorted(n for n in poses if n in truth)
    true = np.stack([truth[n][:3, 3] for n in names])
    est = np.stack([poses[n][:3, 3] for n in names])
    fit = umeyama(est, true)
    return true, fit.apply(est)


def figures(scenes: list[str], runs: Path, out: Path) -> None:
    """presets_centres.png (centres from above, true and fitted) and presets_look.jpg (a render each)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    fig, axes = plt.subplots(1, len(scenes), figsize=(3.2 * len(scenes), 3.4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        scan, sfm = outputs(scene, runs)
        if (sfm / "sparse" / "0").exists():
            true, est = fitted_centres(scan, sfm)
            ax.scatter(true[:, 0], true[:, 1], s=10, facecolors="none", edgecolors="tab:blue", label="true")
            ax.scatter(est[:, 0], est[:, 1], s=3, color="tab:red", label="fitted model")
        ax.set_title(scene, fontsize=9)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
    axes[0][0].legend(fontsize=7, loc="lower left")
    fig.suptitle("camera centres from above (m): true and COLMAP's, after the similarity fit", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "presets_centres.png", dpi=110)
    plt.close(fig)
    tiles = [Image.fromarray(look(scene)).resize((240, 180)) for scene in PRESETS]
    sheet = Image.new("RGB", (240 * len(tiles), 180))
    for k, tile in enumerate(tiles):
        sheet.paste(tile, (240 * k, 0))
    sheet.save(out / "presets_look.jpg", quality=85)


def look(scene: str) -> np.ndarray:
    """One 320x240 render (spp 16) of `scene` from radius 2 m, azimuth 30 and elevation 30 degrees."""
    from render.camera import UAVCamera
    from render.renderer import MitsubaRenderer
    from render.settings import RenderSettings
    from render.viewpoint import Viewpoint, viewpoint_to_c2w
    from scenes.catalog import load_scene

    renderer = MitsubaRenderer(load_scene(scene), UAVCamera(320, 240), RenderSettings(spp=16))
    view = Viewpoint(2.0, math.radians(30.0), math.radians(30.0))
    return renderer.render_rgb(viewpoint_to_c2w(view, renderer.center), seed=0)


def main(argv: list[str]) -> int:
    """Run (or reuse) every scene's scan and SfM, write the table, JSON and figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=list(PRESETS))
    parser.add_argument("--runs", type=Path, required=True, help="folder of the scans and SfM outputs")
    parser.add_argument("--out", type=Path, required=True, help="folder of presets.{json,md} and the figures")
    parser.add_argument("--reuse", action="store_true", help="keep scans and SfM outputs already there")
    parser.add_argument("--commit", default="", help="the commit the runs were made at, for the record")
    args = parser.parse_args(argv)
    rows = [row(scene, run_scene(scene, args.runs, args.reuse)) for scene in args.scenes]
    args.out.mkdir(parents=True, exist_ok=True)
    record = {"commit": args.commit,
              "commands": [" ".join(c).replace(str(args.runs), "RUNS") for s in args.scenes
                           for c in commands(s, args.runs)],
              "acceptance": {"registered_share_min": SHARE_MIN,
                             "centre_error_pct_radius_max": CENTRE_MAX_PCT},
              "scenes": rows}
    (args.out / "presets.json").write_text(json.dumps(record, indent=2) + "\n")
    header = (f"# `nbv sfm` on each scene's full 288-view hemisphere scan (320x240, spp 16)\n\nCommit "
              f"{args.commit or '-'}; acceptance: at least {100 * SHARE_MIN:.0f} % of the views in one "
              f"model, "
              f"mean camera-centre error at most {CENTRE_MAX_PCT:g} % of the scan radius (2 m) after the "
              f"similarity fit. Commands (RUNS: the runs folder):\n\n"
              + "".join(f"    {c}\n" for c in record["commands"]) + "\n")
    (args.out / "presets.md").write_text(header + markdown(rows))
    figures(args.scenes, args.runs, args.out)
    print(markdown(rows), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
