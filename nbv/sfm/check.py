"""`nbv sfm`: COLMAP on a view dataset, its models written and scored against the dataset's poses.

The output folder (written atomically) holds `images/` (relative links to the dataset's RGB images,
COLMAP's image names), `sparse/0/` (the model with the most registered views, COLMAP's binary format;
further models in `sparse/1/`, ...) and `sfm.json` (the report of `nbv.sfm.report`, with the run
record).
COLMAP's database lives in a scratch folder beside it, removed at the end.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pycolmap

from common.io import atomic_folder, check_separate, scratch_folder, write_json
from common.provenance import run_record
from nbv.sfm.config import SfmConfig, SfmSettings
from nbv.sfm.pipeline import SfmRun, run_sfm
from nbv.sfm.report import sfm_report
from render.dataset import ViewDataset, read_dataset

SUMMARY_KEYS = ("views", "registered", "registered_share", "models", "points", "reprojection_error_px",
                "pose_error", "centre_error_world_cm")
"""The report's headline entries, which a command that runs SfM on its views (`nbv plan --sfm`) keeps."""
MIN_VIEWS = 2
"""Fewest views structure from motion can start from (one image pair)."""


def scan_radius(dataset: ViewDataset) -> float:
    """Mean distance of the true camera centres from the scene centre, metres."""
    return float(np.linalg.norm(dataset.poses()[:, :3, 3] - dataset.center, axis=1).mean())


def check_views(dataset: ViewDataset) -> list[str]:
    """The image names COLMAP will see (file names, which must not repeat), refusing too few views."""
    if len(dataset) < MIN_VIEWS:
        raise ValueError(f"{dataset.root}: {len(dataset)} view(s); structure from motion needs at least "
                         f"{MIN_VIEWS}")
    names = [frame.rgb_path.name for frame in dataset.frames]
    if len(set(names)) < len(names):
        raise ValueError(f"{dataset.root}: image file names repeat; COLMAP names images by file name")
    return names


def link_images(dataset: ViewDataset, folder: Path) -> None:
    """Relative links in the new `folder` to the dataset's RGB images (COLMAP's image names): they hold
    when an output folder holding both (`nbv plan --sfm`) is renamed into place."""
    folder.mkdir(parents=True)
    for frame in dataset.frames:
        target = frame.rgb_path.resolve()
        os.symlink(os.path.relpath(target, folder.resolve()), folder / frame.rgb_path.name)


def sfm_views(dataset: ViewDataset, settings: SfmSettings, seed: int, images: Path,
              work: Path) -> tuple[SfmRun, dict[str, Any]]:
    """COLMAP on `dataset` with its images linked into the new folder `images` (COLMAP's database and
    scratch output under `work`); the run and its report."""
    names = check_views(dataset)
    link_images(dataset, images)
    run = run_sfm(images, names, dataset.camera, dataset.poses()[:, :3, 3], settings, seed, work)
    report = sfm_report(run.models, dict(zip(names, dataset.poses(), strict=True)), scan_radius(dataset),
                        world_frame=bool(run.priors))
    report["seconds"] = run.seconds
    return run, report


def write_sfm(dataset: ViewDataset, settings: SfmSettings, seed: int, folder: Path,
              record: dict[str, Any]) -> dict[str, Any]:
    """COLMAP on `dataset` into the new or empty `folder` (images/, sparse/N/, sfm.json holding `record`,
    a run record, and the report); returns the sfm.json document."""
    with scratch_folder(folder) as work:
        run, report = sfm_views(dataset, settings, seed, folder / "images", work)
    for i, model in enumerate(run.models):
        (folder / "sparse" / str(i)).mkdir(parents=True)
        model.write(folder / "sparse" / str(i))
    doc = {**record, "pycolmap": pycolmap.__version__, "dataset": str(dataset.root), **report}
    write_json(folder / "sfm.json", doc)
    return doc


def sfm_summary(dataset: ViewDataset, settings: SfmSettings, seed: int, folder: Path,
                record: dict[str, Any]) -> dict[str, Any]:
    """`write_sfm` into the new folder `folder` (e.g. a plan's out/sfm); the headline entries of its report
    (`SUMMARY_KEYS`), which the calling command keeps in its own document."""
    folder.mkdir()
    doc = write_sfm(dataset, settings, seed, folder, record)
    return {key: doc[key] for key in SUMMARY_KEYS if key in doc}


def sfm_dataset(config: SfmConfig) -> dict[str, Any]:
    """Run `nbv sfm` on `config.dataset` into `config.out` and return its report (also in sfm.json)."""
    check_separate(config.out, config.dataset)
    dataset = read_dataset(config.dataset)
    check_views(dataset)
    with atomic_folder(config.out, config.overwrite) as tmp:
        return write_sfm(dataset, config.sfm, config.seed, tmp, run_record("nbv sfm", config))
