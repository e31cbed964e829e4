"""Offline refinement (Alg. 1): on features, on datasets, through `nbv refine` and `nbv refine-sweep`."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch
from synthetic import write_circle_dataset

from nbv.bov.bag import BagOfViews
from nbv.bov.config import BoVConfig
from nbv.bov.refine import RefineConfig, frame_azimuths, refine_dataset, refine_views
from nbv.cli import main
from nbv.features.config import FeatureConfig
from render.dataset import DatasetError, read_dataset

E = torch.eye(4)
SMALL = ["--max-features", "40"]
SIFT = FeatureConfig(max_features=40)


@pytest.fixture(scope="module")
def source(tmp_path_factory) -> Path:
    """Eight views: texture a, a again, flat, b, b, c, flat, a."""
    return write_circle_dataset(tmp_path_factory.mktemp("src") / "ds", [0, 0, None, 1, 1, 2, None, 0])


def test_docstring_toy():
    result = refine_views([E[:2], E[:1], E[:0], E[2:3], E[3:4]], [0.5, 1.0, 4.0, 2.0, 3.5],
                          BagOfViews(2, 1, dim=4, match_cosine=0.5))
    assert result.kept == [0, 3, 4] and result.ranges == [0, 0, 1, 0, 1]
    assert result.scores[0] == math.inf and result.scores[2] == 0.0


def test_first_view_kept_repeat_and_flat_dropped(source, tmp_path):
    cache = tmp_path / "cache"
    one = refine_dataset(RefineConfig(dataset=source, out=tmp_path / "one",
                                      bov=BoVConfig(ranges=1, words=30, sift=SIFT), cache_dir=cache))
    assert one["kept"][0] == 0 and 1 not in one["kept"]  # an identical repeat brings nothing new
    assert 2 not in one["kept"] and 6 not in one["kept"]  # no keypoints: score 0, dropped
    assert one["scores"][0] is None and one["scores"][1] < 0 and one["scores"][2] == 0.0
    # One range per view: every view is the first of its range, kept unless it has no keypoints.
    each = refine_dataset(RefineConfig(dataset=source, out=tmp_path / "each",
                                       bov=BoVConfig(ranges=8, words=30, sift=SIFT), cache_dir=cache))
    assert each["kept"] == [0, 1, 3, 4, 5, 7] and each["ranges"] == list(range(8))
    assert [s is None for s in each["scores"]] == [True, True, False, True, True, True, False, True]


def test_refined_dataset_is_readable_and_traceable(source, tmp_path):
    out = tmp_path / "out"
    bov = BoVConfig(ranges=2, words=5, sift=SIFT)
    summary = refine_dataset(RefineConfig(dataset=source, out=out, bov=bov, cache_dir=tmp_path / "cache"))
    doc = json.loads((out / "refine.json").read_text())
    assert doc["kept"] == summary["kept"] and doc["settings"]["ranges"] == 2 and len(doc["ranges"]) == 8
    refined, src = read_dataset(out), read_dataset(source)
    assert [f.meta["source_index"] for f in refined.frames] == doc["kept"]
    for j, i in enumerate(doc["kept"]):
        np.testing.assert_array_equal(refined.rgb(j), src.rgb(i))
        np.testing.assert_allclose(refined.frames[j].c2w, src.frames[i].c2w, atol=1e-9)


def test_same_input_and_seed_same_kept(source, tmp_path):
    bov = BoVConfig(ranges=3, words=4, sift=SIFT)
    config = RefineConfig(dataset=source, out=tmp_path / "a", bov=bov, cache_dir=tmp_path / "cache", seed=3)
    a = refine_dataset(config)
    b = refine_dataset(replace(config, out=tmp_path / "b"))
    assert a["kept"] == b["kept"] and a["scores"] == b["scores"]


def test_azimuth_from_pose_when_no_viewpoint(tmp_path):
    with_vp = read_dataset(write_circle_dataset(tmp_path / "a", [0, 1, 2, 3, 4]))
    without = read_dataset(write_circle_dataset(tmp_path / "b", [0, 1, 2, 3, 4], record_viewpoints=False))
    assert without.frames[0].viewpoint is None
    np.testing.assert_allclose(frame_azimuths(without), frame_azimuths(with_vp), atol=1e-9)
    np.testing.assert_allclose(frame_azimuths(with_vp), 2 * np.pi * np.arange(5) / 5, atol=1e-9)


def test_cli_refine_and_sweep(source, tmp_path):
    cache = ["--cache-dir", str(tmp_path / "cache")]
    assert main(["refine", str(source), "--ranges", "2", "--words", "5", "--out", str(tmp_path / "r"),
                 *SMALL, *cache]) == 0
    kept = json.loads((tmp_path / "r" / "refine.json").read_text())["kept"]
    assert len(read_dataset(tmp_path / "r")) == len(kept)
    assert main(["refine-sweep", str(source), "--ranges", "1", "2", "--words", "5", "30",
                 "--out", str(tmp_path / "s"), *SMALL, *cache]) == 0
    assert len(list((tmp_path / "cache" / "").glob("*.pt"))) == 1  # features extracted once
    with open(tmp_path / "s" / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(r["ranges"], r["words"]) for r in rows] == [("1", "5"), ("1", "30"), ("2", "5"), ("2", "30")]
    assert next(int(r["kept_views"]) for r in rows if r["ranges"] == "2" and r["words"] == "5") == len(kept)
    assert "N=2 W=30" in (tmp_path / "s" / "sweep.md").read_text()


def test_cli_bad_input(source, tmp_path, capsys):
    assert main(["refine", str(source), "--ranges", "0", "--out", str(tmp_path / "x")]) == 2
    assert "ranges and words must be >= 1" in capsys.readouterr().err
    assert main(["refine-sweep", str(source), "--words", "0", "--out", str(tmp_path / "x")]) == 2
    assert main(["refine", str(tmp_path / "nowhere"), "--out", str(tmp_path / "x")]) == 2
    assert "transforms.json" in capsys.readouterr().err


def test_dataset_without_images(tmp_path):
    broken = write_circle_dataset(tmp_path / "ds", [0, 1])
    (broken / "images" / "0001.png").unlink()
    with pytest.raises(DatasetError, match="missing file"):
        refine_dataset(RefineConfig(dataset=broken, out=tmp_path / "out", cache_dir=tmp_path / "cache"))
    empty = write_circle_dataset(tmp_path / "empty", [0])
    doc = json.loads((empty / "transforms.json").read_text())
    (empty / "transforms.json").write_text(json.dumps({**doc, "frames": []}))
    with pytest.raises(DatasetError, match="transforms.json: field frames is empty"):
        refine_dataset(RefineConfig(dataset=empty, out=tmp_path / "out", cache_dir=tmp_path / "cache"))


def test_refuses_to_overwrite(source, tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "keep.txt").write_text("mine")
    with pytest.raises(FileExistsError):
        refine_dataset(RefineConfig(dataset=source, out=tmp_path / "out", cache_dir=tmp_path / "cache"))
    assert (tmp_path / "out" / "keep.txt").read_text() == "mine"
