"""Image quality against a reference: PSNR and SSIM (for render settings measured against a high-spp render).

Both take images of the same shape, uint8 (peak 255) or float in [0, 1] (peak
1). SSIM is Wang et al. (2004): an 11 x 11 Gaussian window of sigma 1.5, K1 =
0.01, K2 = 0.03, computed per channel and averaged over the valid (fully
windowed) pixels and the channels.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter

SSIM_SIGMA = 1.5
"""Standard deviation of SSIM's Gaussian window, pixels."""
SSIM_RADIUS = 5
"""Half-width of SSIM's window (11 x 11 pixels)."""


def _pair(image: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Both images as float64 and their peak value; refuses shapes or dtypes that differ."""
    if image.shape != reference.shape:
        raise ValueError(f"image {image.shape} and reference {reference.shape} differ in shape")
    if image.dtype != reference.dtype:
        raise ValueError(f"image ({image.dtype}) and reference ({reference.dtype}) differ in dtype")
    peak = 255.0 if image.dtype == np.uint8 else 1.0
    return image.astype(np.float64), reference.astype(np.float64), peak


def psnr(image: np.ndarray, reference: np.ndarray) -> float:
    """Peak signal-to-noise ratio in dB, 10 log10(peak^2 / MSE); +inf for identical images.

    Example:
        >>> round(psnr(np.full((4, 4), 110, np.uint8), np.full((4, 4), 100, np.uint8)), 2)
        28.13
    """
    a, b, peak = _pair(image, reference)
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0.0 else 10.0 * float(np.log10(peak**2 / mse))


def ssim(image: np.ndarray, reference: np.ndarray) -> float:
    """Mean structural similarity in [-1, 1] (1: identical) of H x W or H x W x C images, at least 11 x 11."""
    a, b, peak = _pair(image, reference)
    if a.ndim not in (2, 3) or min(a.shape[:2]) < 2 * SSIM_RADIUS + 1:
        raise ValueError(f"ssim needs H x W (x C) images of at least {2 * SSIM_RADIUS + 1} pixels a side, "
                         f"got {a.shape}")
    if a.ndim == 2:
        a, b = a[..., None], b[..., None]
    c1, c2 = (0.01 * peak) ** 2, (0.03 * peak) ** 2
    scores = []
    for ch in range(a.shape[2]):
        x, y = a[..., ch], b[..., ch]

        def blur(v: np.ndarray) -> np.ndarray:
            return gaussian_filter(v, SSIM_SIGMA, truncate=SSIM_RADIUS / SSIM_SIGMA)[
                SSIM_RADIUS:-SSIM_RADIUS, SSIM_RADIUS:-SSIM_RADIUS]

        mx, my = blur(x), blur(y)
        vx, vy, cov = blur(x * x) - mx * mx, blur(y * y) - my * my, blur(x * y) - mx * my
        scores.append(((2 * mx * my + c1) * (2 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2)))
    return float(np.mean(scores))
