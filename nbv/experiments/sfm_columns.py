"""The structure-from-motion columns of the planner studies' tables (with --sfm): views registered in
the largest model (k/N), models, and the largest model's mean camera-centre error after a similarity fit.

A run's SfM headline is plan.json's `sfm` (`nbv.sfm.check.SUMMARY_KEYS`); a table cell describes a
planner's runs over seeds, one k/N per seed, the mean of the rest.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from common.io import markdown_table

SFM_HEADER = ("registered", "models", "centre error (cm)")
"""The columns' headers, after a table's own."""


def sfm_entry(doc: dict[str, Any]) -> dict[str, Any]:
    """The table's view of a plan's (or a demo set's) SfM headline: views, registered, models and the mean
    camera-centre error in cm (None when too few views registered for a fit)."""
    pose = doc.get("pose_error")
    return {"views": doc["views"], "registered": doc["registered"], "models": doc["models"],
            "centre_error_cm": pose["centre_error_cm"]["mean"] if pose else None}


def sfm_cells(entries: list[dict[str, Any]]) -> list[str]:
    """The three cells of a planner's runs (`sfm_entry` each): k/N per run, mean models, mean centre error
    over the runs that have one ('-' for none).

    Example:
        >>> sfm_cells([{"views": 13, "registered": 9, "models": 2, "centre_error_cm": 3.0},
        ...            {"views": 13, "registered": 0, "models": 0, "centre_error_cm": None}])
        ['9/13, 0/13', '1.0', '3.0 (1 run)']
    """
    registered = ", ".join(f"{e['registered']}/{e['views']}" for e in entries)
    models = f"{np.mean([e['models'] for e in entries]):.1f}"
    errors = [e["centre_error_cm"] for e in entries if e["centre_error_cm"] is not None]
    if not errors:
        return [registered, models, "-"]
    error = f"{np.mean(errors):.1f}"
    return [registered, models, error if len(errors) == len(entries) else f"{error} ({len(errors)} run"
            f"{'s' if len(errors) > 1 else ''})"]


def sfm_table(runs: dict[str, dict[str, list[dict[str, Any]]]]) -> str:
    """A Markdown table of the SfM columns, one row per building and planner of `runs` (building -> planner
    label -> its runs, each with an `sfm` entry as `nbv compare` records it)."""
    rows = [[scene, label, *sfm_cells([r["sfm"] for r in mine])]
            for scene, by_planner in runs.items() for label, mine in by_planner.items()]
    return markdown_table(["building", "planner", *SFM_HEADER], rows)


def planned_sfm_table(runs: list[Any]) -> str:
    """A Markdown table of the SfM columns of a study's plan runs (`StudyRun`s; a prefix shares its plan's
    folder, so each plan counts once), one row per building, planner and planned view count."""
    groups: dict[tuple[str, str, int], list[dict[str, Any]]] = {}
    for folder, run in {run.folder: run for run in runs}.items():
        doc = json.loads((folder / "plan.json").read_text())
        groups.setdefault((run.scene, run.label, doc["views"]), []).append(sfm_entry(doc["sfm"]))
    rows = [[scene, label, str(views), *sfm_cells(found)] for (scene, label, views), found in groups.items()]
    return markdown_table(["building", "planner", "views", *SFM_HEADER], rows)
