"""The similarity (scale, rotation, translation) that best maps one point set onto another: Umeyama's fit.

S. Umeyama, "Least-squares estimation of transformation parameters between two point patterns",
IEEE TPAMI 13(4), 1991: the least-squares s, R, t of dst ~ s R src + t, with R a proper rotation (the
SVD's reflection removed). A structure-from-motion model is known up to such a similarity, so its camera
centres are compared with the true ones only after it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Similarity:
    """x -> scale * rotation @ x + translation."""

    scale: float
    """Positive scale factor."""
    rotation: np.ndarray
    """(3, 3) proper rotation."""
    translation: np.ndarray
    """(3,) translation, in the target's units."""

    def apply(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) points mapped into the target frame."""
        return self.scale * np.asarray(points, np.float64) @ self.rotation.T + self.translation


def umeyama(src: np.ndarray, dst: np.ndarray) -> Similarity:
    """The least-squares similarity mapping the (N, 3) points `src` onto `dst` (N >= 3, not collinear).

    Example:
        >>> src = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
        >>> fit = umeyama(src, 2 * src + [1.0, 2.0, 3.0])
        >>> round(fit.scale, 9), fit.translation.round(9).tolist()
        (2.0, [1.0, 2.0, 3.0])
    """
    src, dst = np.asarray(src, np.float64), np.asarray(dst, np.float64)
    if src.shape != dst.shape or src.ndim != 2 or src.shape[1] != 3:
        raise ValueError(f"umeyama needs two (N, 3) point sets of one shape, got {src.shape} and {dst.shape}")
    if len(src) < 3:
        raise ValueError(f"umeyama needs at least 3 point pairs, got {len(src)}")
    mu_src, mu_dst = src.mean(0), dst.mean(0)
    a, b = src - mu_src, dst - mu_dst
    var_src = (a**2).sum() / len(src)
    u, d, vt = np.linalg.svd(b.T @ a / len(src))
    if var_src <= 0 or d[1] <= 1e-12 * max(d[0], 1e-300):
        raise ValueError("umeyama needs points that are not all on one line")
    sign = np.diag([1.0, 1.0, np.sign(np.linalg.det(u) * np.linalg.det(vt)) or 1.0])
    rotation = u @ sign @ vt
    scale = float(np.trace(np.diag(d) @ sign) / var_src)
    return Similarity(scale, rotation, mu_dst - scale * rotation @ mu_src)
