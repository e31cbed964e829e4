"""Geometrically verified SIFT matches between two views: the link that registrability asks for
(`LinkSettings`, docs/sfm.md §5).

The views' own SIFT features (the ones refinement and the planners already extracted, `Features`) are
matched as COLMAP's default verification does: nearest neighbours both ways (cross-check), Lowe's ratio
test at 0.8, then an essential matrix with the known intrinsics by RANSAC (OpenCV, 4 px, seeded); the
link is the number of RANSAC inliers. With our 500 features per view the counts are smaller than
COLMAP's with its 8192, so K is a proxy of COLMAP's own test (15 inliers by default), not the same test.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from nbv.features.sift import Features

RATIO = 0.8
"""Lowe's ratio test: the nearest descriptor must be closer than this times the second nearest (COLMAP's
`max_ratio`)."""
RANSAC_ERROR_PX = 4.0
"""RANSAC's inlier distance to the epipolar line, pixels (COLMAP's `max_error`)."""
RANSAC_CONFIDENCE = 0.999
"""RANSAC's confidence (COLMAP's)."""
MIN_PUTATIVE = 8
"""Fewest ratio-tested matches worth verifying; fewer count as no link."""
RANSAC_SEED = 0
"""OpenCV's RNG seed before each RANSAC, so a link count is the same every run."""


def ratio_tested(a: np.ndarray, b: np.ndarray) -> dict[int, int]:
    """Each row of `a` whose nearest row of `b` (L2) passes the ratio test -> that row."""
    pairs = cv2.BFMatcher(cv2.NORM_L2).knnMatch(a, b, k=2)
    return {m.queryIdx: m.trainIdx for m, n in pairs if m.distance < RATIO * n.distance}


def putative_matches(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(P, 2) index pairs of the (M, 128) descriptors `a` and (N, 128) `b` that are mutual nearest
    neighbours and pass the ratio test in both directions."""
    if len(a) < 2 or len(b) < 2:
        return np.zeros((0, 2), np.int64)
    forward, backward = ratio_tested(a, b), ratio_tested(b, a)
    return np.array([(i, j) for i, j in forward.items() if backward.get(j) == i], np.int64).reshape(-1, 2)


def verified_matches(a: Features, b: Features, K: np.ndarray) -> int:  # noqa: N803 - the standard name
    """The number of matches between two views' features that an essential matrix (intrinsics `K`,
    OpenCV's convention) verifies by RANSAC; 0 below `MIN_PUTATIVE` putative matches.

    Example:
        >>> none = Features.empty()
        >>> verified_matches(none, none, np.eye(3))
        0
    """
    pairs = putative_matches(a.descriptors.cpu().numpy(), b.descriptors.cpu().numpy())
    if len(pairs) < MIN_PUTATIVE:
        return 0
    pa = a.keypoints.cpu().numpy()[pairs[:, 0]].astype(np.float64)
    pb = b.keypoints.cpu().numpy()[pairs[:, 1]].astype(np.float64)
    cv2.setRNGSeed(RANSAC_SEED)
    essential, inliers = cv2.findEssentialMat(pa, pb, np.asarray(K, np.float64), method=cv2.RANSAC,
                                              prob=RANSAC_CONFIDENCE, threshold=RANSAC_ERROR_PX)
    return 0 if essential is None or inliers is None else int(inliers.sum())


def nearest_pairs(centres: np.ndarray, neighbours: int) -> list[tuple[int, int]]:
    """The pairs i < j with j among i's `neighbours` nearest by the (N, 3) `centres` or i among j's, sorted.

    Example:
        >>> nearest_pairs(np.array([[0.0, 0, 0], [1, 0, 0], [3, 0, 0], [7, 0, 0]]), 1)
        [(0, 1), (1, 2), (2, 3)]
    """
    centres = np.asarray(centres, np.float64)
    distance = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    np.fill_diagonal(distance, np.inf)
    pairs = set()
    for i, row in enumerate(distance):
        for j in np.argsort(row, kind="stable")[:neighbours]:
            if np.isfinite(row[j]):
                pairs.add((min(i, int(j)), max(i, int(j))))
    return sorted(pairs)


def link_graph(features: Sequence[Features], centres: np.ndarray, K: np.ndarray,  # noqa: N803
               neighbours: int) -> dict[tuple[int, int], int]:
    """Verified matches of every pair of `nearest_pairs` (views' `features`, camera `centres`): the
    match graph a refinement repairs, {(i, j): matches} with i < j."""
    pairs = nearest_pairs(centres, neighbours)
    return {(i, j): verified_matches(features[i], features[j], K) for i, j in pairs}
