"""Keypoint repeatability between two views, with ground-truth correspondences from depth and poses.

Repeatability (Mikolajczyk and Schmid 2005): of the keypoints of view A whose
surface point is seen by view B, the share that land within `tol_px` pixels of
a keypoint of B. A keypoint of A is carried to B through A's z-depth at its
(nearest) pixel and the two camera poses (OpenCV camera-to-world, K with pixel
centres at integers, docs/conventions.md); it counts as seen when it has depth,
projects in front of B and inside B's image, and (given B's depth) is not hidden
there. For two renders of one pose the projection is the identity and
repeatability is the share of A's keypoints that B finds again in place.
"""

from __future__ import annotations

import numpy as np

OCCLUSION_RTOL = 0.02
"""A carried point is hidden in B when it lies this fraction farther than B's depth at its pixel."""


def carry_keypoints(keypoints: np.ndarray, depth_a: np.ndarray, K_a: np.ndarray, c2w_a: np.ndarray,
                    K_b: np.ndarray, c2w_b: np.ndarray, depth_b: np.ndarray | None = None,
                    ) -> tuple[np.ndarray, np.ndarray]:
    """View A's keypoints (M, 2) pixel (x, y) as pixels of view B, and which of them B sees (M,) bool.

    B's image has `depth_b`'s size (A's without it); without `depth_b` nothing counts as hidden."""
    kp = np.asarray(keypoints, dtype=np.float64).reshape(-1, 2)
    h, w = depth_a.shape
    cols = np.clip(np.round(kp[:, 0]).astype(int), 0, w - 1)
    rows = np.clip(np.round(kp[:, 1]).astype(int), 0, h - 1)
    z = depth_a[rows, cols].astype(np.float64)
    rays = np.linalg.solve(K_a, np.stack([kp[:, 0], kp[:, 1], np.ones(len(kp))]))
    world = c2w_a[:3, :3] @ (rays * z) + c2w_a[:3, 3:4]
    in_b = np.linalg.inv(c2w_b)[:3] @ np.vstack([world, np.ones(len(kp))])
    front = in_b[2] > 1e-9
    pix = (K_b @ in_b)[:2] / np.where(front, in_b[2], 1.0)
    pixels = pix.T
    hb, wb = (depth_b.shape if depth_b is not None else depth_a.shape)
    seen = (z > 0) & front & (pixels[:, 0] > -0.5) & (pixels[:, 0] < wb - 0.5) & (pixels[:, 1] > -0.5) \
        & (pixels[:, 1] < hb - 0.5)
    if depth_b is not None:
        cb = np.clip(np.round(pixels[:, 0]).astype(int), 0, wb - 1)
        rb = np.clip(np.round(pixels[:, 1]).astype(int), 0, hb - 1)
        zb = depth_b[rb, cb]
        seen &= (zb > 0) & (in_b[2] <= zb * (1.0 + OCCLUSION_RTOL))
    return pixels, seen


def repeatability(keypoints_a: np.ndarray, keypoints_b: np.ndarray, depth_a: np.ndarray, K_a: np.ndarray,
                  c2w_a: np.ndarray, K_b: np.ndarray | None = None, c2w_b: np.ndarray | None = None,
                  depth_b: np.ndarray | None = None, tol_px: float = 1.0) -> float:
    """Share in [0, 1] of A's keypoints seen by B that have a keypoint of B within `tol_px` pixels.

    Args:
        keypoints_a, keypoints_b: (M, 2) and (N, 2) pixel (x, y), pixel centres at integers.
        depth_a: H x W z-depth of view A in metres (0: no surface).
        K_a, c2w_a: view A's intrinsics and OpenCV camera-to-world.
        K_b, c2w_b: view B's; default: A's (two renders of one pose).
        depth_b: view B's z-depth, to drop points hidden in B (and B's image size); None: no occlusion
            test, and B's image has A's size.
        tol_px: the match radius, pixels.

    Returns:
        The repeatability; 0 when no keypoint of A is seen by B.

    Example:
        >>> K = np.array([[50.0, 0, 31.5], [0, 50, 23.5], [0, 0, 1]])
        >>> pose, depth = np.eye(4), np.ones((48, 64))
        >>> repeatability(np.array([[10.0, 10], [20, 20]]), np.array([[10.4, 10]]), depth, K, pose)
        0.5
    """
    K_b = K_a if K_b is None else K_b
    c2w_b = c2w_a if c2w_b is None else c2w_b
    pixels, seen = carry_keypoints(keypoints_a, depth_a, K_a, c2w_a, K_b, c2w_b, depth_b)
    if not seen.any():
        return 0.0
    kb = np.asarray(keypoints_b, dtype=np.float64).reshape(-1, 2)
    if len(kb) == 0:
        return 0.0
    gaps = np.linalg.norm(pixels[seen][:, None, :] - kb[None, :, :], axis=2).min(axis=1)
    return float(np.mean(gaps <= tol_px))


LOWE_RATIO = 0.8
"""A match is kept when its descriptor distance is below this fraction of the second-nearest's (Lowe 2004)."""


def match_descriptors(descriptors_a: np.ndarray, descriptors_b: np.ndarray,
                      ratio: float = LOWE_RATIO) -> np.ndarray:
    """(K, 2) index pairs (a, b) of mutual nearest neighbours (Euclidean) that pass Lowe's ratio test."""
    a = np.asarray(descriptors_a, dtype=np.float64).reshape(-1, np.shape(descriptors_a)[-1])
    b = np.asarray(descriptors_b, dtype=np.float64).reshape(-1, a.shape[1])
    if len(a) == 0 or len(b) == 0:
        return np.zeros((0, 2), dtype=int)
    dist = np.sqrt(np.maximum((a * a).sum(1)[:, None] + (b * b).sum(1)[None] - 2.0 * a @ b.T, 0.0))
    nearest_b, nearest_a = dist.argmin(axis=1), dist.argmin(axis=0)
    mutual = nearest_a[nearest_b] == np.arange(len(a))
    if len(b) > 1:
        two = np.sort(dist, axis=1)[:, :2]
        mutual &= two[:, 0] < ratio * two[:, 1]
    rows = np.flatnonzero(mutual)
    return np.stack([rows, nearest_b[rows]], axis=1)


def match_inlier_ratio(keypoints_a: np.ndarray, descriptors_a: np.ndarray, keypoints_b: np.ndarray,
                       descriptors_b: np.ndarray, depth_a: np.ndarray, K_a: np.ndarray, c2w_a: np.ndarray,
                       K_b: np.ndarray | None = None, c2w_b: np.ndarray | None = None,
                       depth_b: np.ndarray | None = None, tol_px: float = 1.0) -> float:
    """Share in [0, 1] of descriptor matches (`match_descriptors`) between A and B that are correct: A's
    keypoint, carried to B through depth and poses (`carry_keypoints`) and seen there, lands within `tol_px`
    of its match. Matches of A's keypoints B cannot see do not count; 0 when no match counts.

    Example:
        >>> K = np.array([[50.0, 0, 31.5], [0, 50, 23.5], [0, 0, 1]])
        >>> kp, desc = np.array([[10.0, 10], [20, 20]]), np.eye(2)
        >>> match_inlier_ratio(kp, desc, kp[::-1], desc, np.ones((48, 64)), K, np.eye(4))
        0.0
    """
    K_b = K_a if K_b is None else K_b
    c2w_b = c2w_a if c2w_b is None else c2w_b
    pairs = match_descriptors(descriptors_a, descriptors_b)
    pixels, seen = carry_keypoints(keypoints_a, depth_a, K_a, c2w_a, K_b, c2w_b, depth_b)
    pairs = pairs[seen[pairs[:, 0]]] if len(pairs) else pairs
    if len(pairs) == 0:
        return 0.0
    kb = np.asarray(keypoints_b, dtype=np.float64).reshape(-1, 2)
    gaps = np.linalg.norm(pixels[pairs[:, 0]] - kb[pairs[:, 1]], axis=1)
    return float(np.mean(gaps <= tol_px))
