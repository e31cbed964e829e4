"""`nbv sfm DATASET --out DIR`: COLMAP's structure from motion on a view dataset, scored against its poses."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.sfm.config import SfmConfig


def summary_line(report: dict) -> str:
    """One line: views registered, models, points, reprojection error and the centre error after the fit."""
    if not report["models"]:
        return f"no model: 0 of {report['views']} views registered"
    line = (f"{report['registered']} of {report['views']} views registered in the largest of "
            f"{report['models']} model(s), {report['points']} points, reprojection error "
            f"{report['reprojection_error_px']:.2f} px")
    error = report["pose_error"]
    if error is not None:
        centre, pct = error["centre_error_cm"], error["centre_error_pct_radius"]
        line += (f"; camera centres after a similarity fit: mean {centre['mean']:.2f} cm "
                 f"({pct['mean']:.2f} % of the scan radius), max {centre['max']:.2f} cm; rotation "
                 f"median {error['rotation_error_deg']['median']:.2f} deg, relative median "
                 f"{error['relative_rotation_error_deg']['median']:.2f} deg")
    return line


def main(args: Sequence[str], prog: str) -> int:
    """Parse `SfmConfig`, run COLMAP, write the models and sfm.json, print the summary."""
    from nbv.sfm.check import sfm_dataset

    config = parse(SfmConfig, args, prog)
    report = sfm_dataset(config)
    print(summary_line(report))
    print(config.out / "sfm.json")
    return 0
