"""Issue 29's structure-from-motion measurements, re-run with `nbv sfm`: arcs and orbits of a preset.

Each case renders a ring of views (radius 2 m, elevation 30 degrees, spp 16; cached under
$NBV_CACHE_DIR/sfm_measure) and runs `nbv sfm` on it (exhaustive matching, intrinsics fixed), then
prints one Markdown row per case: views registered, models, points, reprojection error and the camera
centre and rotation errors after the similarity fit.

    nice -n 5 python scripts/sfm_measure.py --out sfm_out                      # the issue's two cases
    nice -n 5 python scripts/sfm_measure.py --out sfm_out --cases arc640 arc640@40 orbit36x640

Cases: `arc640` (12 views 10 degrees apart from azimuth 0, 640x480), `arc640@DEG` (the same arc from
azimuth DEG), `orbit13x320` (13 views evenly round, 320x240), `orbit36x640` (36 views, 640x480).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from common.io import cache_dir, markdown_table
from nbv.sfm.check import sfm_dataset
from nbv.sfm.config import SfmConfig
from render.camera import UAVCamera
from render.scan_cache import ensure_scan
from render.settings import RenderSettings
from render.viewpoint import Viewpoint
from scenes.catalog import load_scene

RADIUS_M, ELEVATION_DEG, SPP = 2.0, 30.0, 16
"""The ring every case flies (CirclePlan's defaults) and the samples per pixel of its renders."""


def case_views(case: str) -> tuple[UAVCamera, list[Viewpoint]]:
    """The camera and viewpoints of a case name (module docstring)."""
    elevation = math.radians(ELEVATION_DEG)
    if case.startswith("arc640"):
        start = float(case.partition("@")[2] or 0.0)
        return UAVCamera(640, 480), [Viewpoint(RADIUS_M, math.radians(start + 10.0 * i), elevation)
                                     for i in range(12)]
    if case.startswith("orbit"):
        count, _, size = case.removeprefix("orbit").partition("x")
        width = int(size)
        return UAVCamera(width, width * 3 // 4), [Viewpoint(RADIUS_M, 2 * math.pi * i / int(count), elevation)
                                                  for i in range(int(count))]
    raise ValueError(f"unknown case {case!r} (arc640, arc640@DEG, orbitNxW)")


def row(case: str, report: dict) -> list[str]:
    """One table row of a case's report."""
    error = report["pose_error"]
    fit = ["-"] * 4 if error is None else [
        f"{error['centre_error_cm']['mean']:.2f}", f"{error['centre_error_cm']['max']:.2f}",
        f"{error['centre_error_pct_radius']['mean']:.2f}", f"{error['rotation_error_deg']['median']:.2f}"]
    reproj = report["reprojection_error_px"]
    return [case, f"{report['registered']} / {report['views']}", str(report["models"]),
            str(report["points"]), "-" if reproj is None else f"{reproj:.2f}", *fit]


def main(argv: list[str]) -> int:
    """Render (or reuse) each case's views, run `nbv sfm` on them, print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="medieval_tavern")
    parser.add_argument("--cases", nargs="+", default=["arc640", "orbit13x320"])
    parser.add_argument("--out", type=Path, required=True, help="folder of the `nbv sfm` outputs")
    args = parser.parse_args(argv)
    scene, rows = load_scene(args.scene), []
    for case in args.cases:
        camera, views = case_views(case)
        folder = cache_dir() / "sfm_measure" / f"{args.scene}-{case}"
        ensure_scan(scene, camera, views, folder, RenderSettings(spp=SPP), progress=False)
        report = sfm_dataset(SfmConfig(dataset=folder, out=args.out / case, overwrite=True))
        rows.append(row(case, report))
        print(markdown_table(HEADER, rows[-1:]).splitlines()[-1], flush=True)
    print(markdown_table(HEADER, rows), end="")
    return 0


HEADER = ["case", "registered", "models", "points", "reproj. px", "centre mean cm", "centre max cm",
          "centre mean % R", "rotation median deg"]
"""Columns of the printed table."""

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
