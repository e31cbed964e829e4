"""Tileable noise fields for procedural textures (NumPy only).

Every field here is periodic over the image, so a texture tiled by UVs with
wrap mode `repeat` shows no seams.
"""

from __future__ import annotations

import numpy as np


def fbm(
    size: int, rng: np.random.Generator, beta: float = 2.0, low: float = 2.0, high: float | None = None
) -> np.ndarray:
    """Fractal (1/f^beta) noise by spectral synthesis, normalised to zero mean and unit std.

    Args:
        size: side of the square image, pixels.
        rng: random source.
        beta: spectral exponent; 2 gives cloudy stains, 1 grainy detail.
        low: lowest spatial frequency kept, cycles per image.
        high: highest frequency kept (default: Nyquist).

    Returns:
        (size, size) float64 periodic field.
    """
    fy = np.fft.fftfreq(size)[:, None] * size
    fx = np.fft.rfftfreq(size)[None, :] * size
    radius = np.hypot(fy, fx)
    keep = (radius >= low) & (radius <= (high if high is not None else size / 2))
    amplitude = np.where(keep, np.power(np.maximum(radius, 1.0), -beta / 2.0), 0.0)
    field = np.fft.irfft2(amplitude * np.exp(2j * np.pi * rng.random(radius.shape)), s=(size, size))
    return (field - field.mean()) / (field.std() + 1e-12)


def anisotropic_fbm(size: int, rng: np.random.Generator, stretch: float, beta: float = 1.5) -> np.ndarray:
    """Fractal noise stretched `stretch` times along image rows' vertical axis (wood grain, grass).

    Returns:
        (size, size) float64 periodic field, zero mean and unit std.
    """
    fy = np.fft.fftfreq(size)[:, None] * size * stretch
    fx = np.fft.rfftfreq(size)[None, :] * size
    radius = np.hypot(fy, fx)
    amplitude = np.where(radius >= 1.0, np.power(np.maximum(radius, 1.0), -beta / 2.0), 0.0)
    field = np.fft.irfft2(amplitude * np.exp(2j * np.pi * rng.random(radius.shape)), s=(size, size))
    return (field - field.mean()) / (field.std() + 1e-12)


def voronoi(
    size: int, cells: int, rng: np.random.Generator, jitter: float = 0.9, warp: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Periodic Voronoi (worley) cells seeded one per grid cell of a `cells` x `cells` grid.

    Args:
        size: image side, pixels.
        cells: grid cells per side (the number of stones, pebbles... per row).
        rng: random source.
        jitter: how far (in cell units) each seed may move from its cell centre.
        warp: optional (2, size, size) offsets in cell units that bend cell borders.

    Returns:
        F1 and F2 (distance to nearest and second-nearest seed, cell units) and the
        nearest seed's id, each (size, size).
    """
    offsets = 0.5 + jitter * (rng.random((cells, cells, 2)) - 0.5)
    coords = (np.arange(size) + 0.5) * cells / size
    gy, gx = np.meshgrid(coords, coords, indexing="ij")
    if warp is not None:
        gy, gx = gy + warp[0], gx + warp[1]
    cy, cx = np.floor(gy).astype(int), np.floor(gx).astype(int)
    f1 = np.full((size, size), np.inf)
    f2 = np.full((size, size), np.inf)
    ident = np.zeros((size, size), dtype=np.int64)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            ny, nx = cy + dy, cx + dx
            wy, wx = ny % cells, nx % cells
            sy = ny + offsets[wy, wx, 0]
            sx = nx + offsets[wy, wx, 1]
            dist = np.hypot(gy - sy, gx - sx)
            closer = dist < f1
            f2 = np.where(closer, f1, np.minimum(f2, dist))
            ident = np.where(closer, wy * cells + wx, ident)
            f1 = np.where(closer, dist, f1)
    return f1, f2, ident


def per_cell(ident: np.ndarray, count: int, rng: np.random.Generator, channels: int = 1) -> np.ndarray:
    """A random value in [0, 1) per cell id, broadcast to the image: (H, W, channels)."""
    return rng.random((count, channels))[ident]


def to_uint8(image: np.ndarray) -> np.ndarray:
    """Float RGB in [0, 1] to uint8, clipped."""
    return np.round(np.clip(image, 0.0, 1.0) * 255.0).astype(np.uint8)
