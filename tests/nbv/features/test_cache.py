"""Feature cache: keyed by content and settings, reused, corrupt files rebuilt."""

from __future__ import annotations

import pytest
import torch
from PIL import Image
from synthetic import textured, write_circle_dataset

import nbv.features.cache as fc
from nbv.features.sift import FeatureConfig
from render.camera import UAVCamera
from render.dataset import DatasetWriter, read_dataset
from render.dataset_read import DatasetError

CONFIG = FeatureConfig(max_features=40)


@pytest.fixture()
def dataset(tmp_path):
    return read_dataset(write_circle_dataset(tmp_path / "ds", [0, 1, None]))


def cache_files(folder):
    return sorted(folder.glob("*.pt"))


def test_second_call_reads_the_cache(dataset, tmp_path, monkeypatch):
    first = fc.dataset_features(dataset, CONFIG, tmp_path / "cache")
    assert len(cache_files(tmp_path / "cache")) == 1 and [len(f) > 0 for f in first] == [True, True, False]

    def fail(*args, **kwargs):
        raise AssertionError("features extracted again")

    monkeypatch.setattr(fc, "extract_features", fail)
    second = fc.dataset_features(dataset, CONFIG, tmp_path / "cache")
    for a, b in zip(first, second):
        assert torch.equal(a.descriptors, b.descriptors) and torch.equal(a.keypoints, b.keypoints)


def test_key_follows_content_and_settings(dataset, tmp_path):
    key = fc.cache_key(dataset, CONFIG)
    assert fc.cache_key(dataset, FeatureConfig(max_features=40, batch_size=2)) == key
    assert fc.cache_key(dataset, FeatureConfig(max_features=41)) != key
    assert fc.cache_key(dataset, FeatureConfig(backend="opencv", max_features=40)) != key
    Image.fromarray(textured(72, 96, 7)).save(dataset.frames[0].rgb_path)
    assert fc.cache_key(dataset, CONFIG) != key


@pytest.mark.parametrize("garbage", [b"not a torch file", b""])
def test_corrupt_cache_is_rebuilt(dataset, tmp_path, garbage):
    reference = fc.dataset_features(dataset, CONFIG, tmp_path / "cache")
    (path,) = cache_files(tmp_path / "cache")
    path.write_bytes(garbage)
    with pytest.warns(UserWarning, match="corrupt"):
        rebuilt = fc.dataset_features(dataset, CONFIG, tmp_path / "cache")
    assert all(torch.equal(a.descriptors, b.descriptors) for a, b in zip(reference, rebuilt))
    assert len(fc.load_features(path, 3)) == 3  # the file was rewritten


def test_cache_of_wrong_shape_is_rebuilt(dataset, tmp_path):
    fc.dataset_features(dataset, CONFIG, tmp_path / "cache")
    (path,) = cache_files(tmp_path / "cache")
    doc = torch.load(path, weights_only=True)
    doc["descriptors"] = doc["descriptors"][:, :64]
    torch.save(doc, path)
    with pytest.raises(ValueError, match="shapes"):
        fc.load_features(path, 3)
    with pytest.warns(UserWarning, match="corrupt"):
        fc.dataset_features(dataset, CONFIG, tmp_path / "cache")


def test_dataset_without_frames(tmp_path):
    with pytest.raises(ValueError, match="no frames were added"), DatasetWriter(tmp_path / "empty",
                                                                               UAVCamera(32, 24), {}):
        pass
    assert not (tmp_path / "empty").exists()


def test_default_cache_dir_follows_env(monkeypatch, tmp_path):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    assert fc.default_cache_dir() == tmp_path / "features"


def test_digest_refuses_a_huge_image_file_unread(dataset, monkeypatch):
    with open(dataset.frames[1].rgb_path, "r+b") as handle:
        handle.truncate(2**40)  # sparse: a terabyte on paper, nothing on disk

    def unbounded(self, *args, **kwargs):
        raise AssertionError("read whole")

    monkeypatch.setattr("pathlib.Path.read_bytes", unbounded)
    with pytest.raises(DatasetError, match=r"0001\.png: file larger than"):
        fc.dataset_digest(dataset)
