"""Spherical k-means: against a brute-force NumPy Lloyd, seeding, warm start, determinism."""

from __future__ import annotations

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from nbv.bov.kmeans import kmeans_plusplus, spherical_kmeans


def unit_rows(n: int, d: int, seed: int) -> torch.Tensor:
    return F.normalize(torch.rand(n, d, generator=torch.Generator().manual_seed(seed)) ** 3, dim=1)


def numpy_lloyd(x: np.ndarray, centres: np.ndarray, iters: int) -> tuple[np.ndarray, np.ndarray]:
    """Reference: explicit loops over points and clusters."""
    centres = centres.copy()
    assign = np.array([int(np.argmax([p @ c for c in centres])) for p in x])
    for _ in range(iters):
        for k in range(len(centres)):
            members = x[assign == k]
            if len(members):
                total = members.sum(axis=0)
                centres[k] = total / np.linalg.norm(total)
        new = np.array([int(np.argmax([p @ c for c in centres])) for p in x])
        if (new == assign).all():
            break
        assign = new
    return centres, assign


def test_lloyd_matches_numpy_reference():
    x = unit_rows(200, 16, 0)
    init = x[:7].clone()
    centres, assign = spherical_kmeans(x, 7, init=init, iters=50)
    ref_centres, ref_assign = numpy_lloyd(x.double().numpy(), init.double().numpy(), 50)
    np.testing.assert_array_equal(assign.numpy(), ref_assign)
    np.testing.assert_allclose(centres.numpy(), ref_centres, atol=1e-5)


def test_recovers_separated_clusters():
    g = torch.Generator().manual_seed(1)
    poles = torch.eye(8)[:4]
    x = F.normalize(poles.repeat_interleave(25, 0) + 0.05 * torch.randn(100, 8, generator=g), dim=1)
    centres, assign = spherical_kmeans(x, 4, generator=torch.Generator().manual_seed(0))
    assert len(set(assign.tolist())) == 4
    assert (centres @ poles.T).amax(dim=0).min() > 0.99
    torch.testing.assert_close(centres.norm(dim=1), torch.ones(4))


def test_kmeans_plusplus_keeps_init_and_is_seeded():
    x = unit_rows(50, 8, 2)
    init = x[:3]
    a = kmeans_plusplus(x, 6, init, torch.Generator().manual_seed(5))
    b = kmeans_plusplus(x, 6, init, torch.Generator().manual_seed(5))
    c = kmeans_plusplus(x, 6, init, torch.Generator().manual_seed(6))
    assert a.shape == (6, 8)
    torch.testing.assert_close(a[:3], init)
    assert torch.equal(a, b) and not torch.equal(a, c)
    # Seeds are data points, never a repeat of a chosen centre while distinct points remain.
    assert len({tuple(r.tolist()) for r in a}) == 6


def test_duplicate_points_still_give_k_centres():
    x = F.normalize(torch.ones(5, 4), dim=1)
    centres, assign = spherical_kmeans(x, 3, generator=torch.Generator().manual_seed(0))
    assert centres.shape == (3, 4) and (assign == 0).all()


@pytest.mark.parametrize("k, init_rows", [(0, 0), (11, 0), (3, 4)])
def test_bad_arguments(k, init_rows):
    x = unit_rows(10, 4, 3)
    with pytest.raises(ValueError):
        spherical_kmeans(x, k, init=x[:init_rows] if init_rows else None)
