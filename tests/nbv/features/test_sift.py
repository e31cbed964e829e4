"""SIFT features: shapes, normalisation, Kornia vs OpenCV agreement, batching, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from scipy.spatial import cKDTree
from synthetic import textured

from nbv.features.sift import FeatureConfig, extract_features


@pytest.fixture(scope="module")
def images() -> np.ndarray:
    return np.stack([textured(96, 128, s) for s in range(3)])


@pytest.mark.parametrize("backend", ["kornia", "opencv"])
def test_shapes_and_normalisation(images, backend):
    feats = extract_features(images, FeatureConfig(backend=backend, max_features=60))
    assert len(feats) == 3
    for f in feats:
        m = len(f)
        assert 10 < m <= 60
        assert f.keypoints.shape == (m, 2) and f.keypoints.dtype == torch.float32
        assert f.descriptors.shape == (m, 128) and f.descriptors.dtype == torch.float32
        assert f.responses.shape == (m,)
        torch.testing.assert_close(f.descriptors.norm(dim=1), torch.ones(m))
        assert (f.descriptors >= 0).all()
        assert (f.keypoints[:, 0] >= 0).all() and (f.keypoints[:, 0] <= 127).all()
        assert (f.keypoints[:, 1] >= 0).all() and (f.keypoints[:, 1] <= 95).all()
        assert (f.responses[:-1] >= f.responses[1:]).all()


def test_kornia_is_sift_like_opencv(images):
    """Same blobs, same descriptors: keypoints within a pixel of OpenCV's carry near-identical SIFT."""
    k = extract_features(images[:1], FeatureConfig(max_features=100))[0]
    o = extract_features(images[:1], FeatureConfig(backend="opencv", max_features=100))[0]
    dist, j = cKDTree(o.keypoints.numpy()).query(k.keypoints.numpy())
    near = dist < 1.0
    assert near.mean() > 0.3
    cos = (k.descriptors[near] * o.descriptors[j[near]]).sum(dim=1)
    assert cos.median() > 0.95


def test_batched_equals_one_by_one(images):
    config = FeatureConfig(max_features=60, batch_size=3)
    batched = extract_features(images, config)
    single = [extract_features(images[i : i + 1], config)[0] for i in range(3)]
    for b, s in zip(batched, single):  # batched convolutions round differently: not bit-identical
        torch.testing.assert_close(b.keypoints, s.keypoints, atol=1e-3, rtol=0)
        torch.testing.assert_close(b.descriptors, s.descriptors, atol=1e-3, rtol=0)


def test_list_of_sizes_and_flat_view():
    flat = np.full((64, 80, 3), 128, np.uint8)
    views = [textured(64, 80, 0), flat, textured(72, 96, 1)]
    for backend in ("kornia", "opencv"):
        feats = extract_features(views, FeatureConfig(backend=backend, max_features=40))
        assert [len(f) > 0 for f in feats] == [True, False, True]
        assert feats[1].descriptors.shape == (0, 128)


@pytest.mark.parametrize("bad, message", [
    (np.zeros((2, 32, 32), np.uint8), "shape"),
    (np.zeros((1, 32, 32, 4), np.uint8), "shape"),
    (np.zeros((1, 32, 32, 3), np.float32), "dtype"),
    ([np.zeros((32, 32), np.uint8)], "shape"),
    (["not an image"], "numpy"),
])
def test_bad_images(bad, message):
    with pytest.raises(ValueError, match=message):
        extract_features(bad, FeatureConfig())


def test_bad_config():
    with pytest.raises(ValueError, match="backend"):
        FeatureConfig(backend="surf")
    with pytest.raises(ValueError, match="max_features"):
        FeatureConfig(max_features=0)
