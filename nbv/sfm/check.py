"""`nbv sfm`: COLMAP on a view dataset, its models written and scored against the dataset's poses.

The output folder (written atomically) holds `images/` (links to the dataset's RGB images, COLMAP's
image names), `sparse/0/` (the model with the most registered views, COLMAP's binary format; further
models in `sparse/1/`, ...) and `sfm.json` (the report of `nbv.sfm.report` with the run record).
COLMAP's database lives in a scratch folder beside it, removed at the end.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pycolmap

from common.io import atomic_folder, check_separate, scratch_folder, write_json
from common.provenance import run_record
from nbv.sfm.config import SfmConfig
from nbv.sfm.pipeline import SfmRun, run_sfm
from nbv.sfm.report import sfm_report
from render.colmap import place_images
from render.dataset import ViewDataset, read_dataset

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


def sfm_views(dataset: ViewDataset, config: SfmConfig, images: Path,
              work: Path) -> tuple[SfmRun, dict[str, Any]]:
    """COLMAP on `dataset` with its images linked into the new folder `images` (COLMAP's database and
    scratch output under `work`); the run and its report."""
    names = check_views(dataset)
    place_images(dataset, images, "link")
    run = run_sfm(images, names, dataset.camera, dataset.poses()[:, :3, 3], config.sfm, config.seed, work)
    report = sfm_report(run.models, dict(zip(names, dataset.poses(), strict=True)), scan_radius(dataset),
                        world_frame=bool(run.priors))
    report["seconds"] = run.seconds
    return run, report


def sfm_dataset(config: SfmConfig) -> dict[str, Any]:
    """Run `nbv sfm` on `config.dataset` into `config.out` and return its report (also in sfm.json)."""
    check_separate(config.out, config.dataset)
    dataset = read_dataset(config.dataset)
    with atomic_folder(config.out, config.overwrite) as tmp, scratch_folder(config.out) as work:
        run, report = sfm_views(dataset, config, tmp / "images", work)
        for i, model in enumerate(run.models):
            (tmp / "sparse" / str(i)).mkdir(parents=True)
            model.write(tmp / "sparse" / str(i))
        doc = {**run_record("nbv sfm", config), "pycolmap": pycolmap.__version__,
               "dataset": str(config.dataset), **report}
        write_json(tmp / "sfm.json", doc)
    return doc
