"""The unique detail baked over a part's atlas (`scenes.detail`): weathering, stains, signs, growth.

Sizes are in real metres of surface (before a building is normalised), so a stain
is as large on a wall as on a roof whatever the material's tile. Every field is
non-periodic noise drawn for this atlas, so no two faces, of one building or of
two, carry the same detail.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

BASE_GROWTH_M = (0.25, 0.9)
"""Range of the height, metres above the ground, up to which dirt and moss climb a wall."""
POSTER_AREA_M2 = 18.0
"""Wall area per poster or sign, on average (large walls only)."""


@dataclass(frozen=True)
class Chart:
    """Where one planar face lies in the atlas and on the building."""

    ou: int
    """Texel column, in the tiled material, of the block's left edge."""
    ov: int
    """Texel row, in the tiled material, of the block's top edge."""
    x: int
    """Atlas column of the block's left edge."""
    y: int
    """Atlas row of the block's top edge."""
    w: int
    """Block width, texels."""
    h: int
    """Block height, texels."""
    frame: np.ndarray
    """(3, 3) affine map from (u, v, 1), in material tiles, to the world position in metres."""

    def positions(self, texel_per_tile: int) -> np.ndarray:
        """(h, w, 3) world position of every texel centre of the block."""
        u = (self.ou + np.arange(self.w) + 0.5) / texel_per_tile
        v = (self.ov + np.arange(self.h) + 0.5) / texel_per_tile
        uu, vv = np.meshgrid(u, v)
        return np.stack([uu, vv, np.ones_like(uu)], -1) @ self.frame.T

    def normal(self) -> np.ndarray:
        """Unit normal of the face (up to sign)."""
        n = np.cross(self.frame[:, 0], self.frame[:, 1])
        return n / (np.linalg.norm(n) + 1e-300)


def value_noise(shape: tuple[int, int], cell_px: tuple[float, float], rng: np.random.Generator) -> np.ndarray:
    """Smooth non-periodic noise of `shape` with features `cell_px` (rows, columns) texels apart, unit std."""
    cy, cx = max(1.0, cell_px[0]), max(1.0, cell_px[1])
    grid = rng.standard_normal((int(shape[0] / cy) + 3, int(shape[1] / cx) + 3)).astype(np.float32)
    size = (int(round(grid.shape[1] * cx)), int(round(grid.shape[0] * cy)))
    field = cv2.resize(grid, size, interpolation=cv2.INTER_CUBIC)[: shape[0], : shape[1]]
    return (field - field.mean()) / (field.std() + 1e-6)


def fractal(shape: tuple[int, int], cells_m: tuple[float, ...], px_per_m: float,
            rng: np.random.Generator, stretch: float = 1.0) -> np.ndarray:
    """Sum of value-noise octaves at `cells_m` metres (amplitude growing with size), unit std; rows
    `stretch` times longer than columns."""
    total = sum(np.sqrt(c) * value_noise(shape, (c * px_per_m * stretch, c * px_per_m), rng) for c in cells_m)
    return total / (total.std() + 1e-6)


def weather(image: np.ndarray, charts: list[Chart], texel_per_tile: int, px_per_m: float,
            rng: np.random.Generator) -> None:
    """Lay the detail over `image` (linear-ish sRGB floats, (H, W, 3)) in place."""
    shape = image.shape[:2]
    half, coarse = ((shape[0] + 1) // 2, (shape[1] + 1) // 2), px_per_m / 2
    stain = np.clip((fractal(half, (1.2, 0.6, 0.3, 0.15), coarse, rng) - 0.8) / 0.5, 0.0, 1.0)
    colour = rng.uniform((0.18, 0.16, 0.1), (0.4, 0.36, 0.3)).astype(np.float32)
    shade = np.exp(0.22 * fractal(half, (4.0, 2.0, 1.0, 0.5), coarse, rng))
    streak = fractal(half, (1.0, 0.5), coarse * 0.08, rng, stretch=12.0)
    shade *= (1.0 - 0.3 * np.clip((streak - 1.0) / 0.6, 0.0, 1.0)) * (1.0 - 0.55 * stain)
    fleck = value_noise(shape, (0.05 * px_per_m,) * 2, rng)
    image *= (_full(shade, shape) * (1.0 - 0.5 * np.clip((fleck - 1.8) / 0.4, 0.0, 1.0)))[..., None]
    image += _full(0.33 * stain, shape)[..., None] * colour
    for chart in charts:
        region = image[chart.y:chart.y + chart.h, chart.x:chart.x + chart.w]
        region *= (rng.uniform(0.82, 1.15) * (1.0 + rng.normal(0.0, 0.05, 3))).astype(np.float32)
        if abs(chart.normal()[2]) < 0.3:
            _wall(region, chart, texel_per_tile, px_per_m, rng)


def _full(field: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """A half-resolution field brought to `shape` (bilinear)."""
    return cv2.resize(field, (field.shape[1] * 2, field.shape[0] * 2), interpolation=cv2.INTER_LINEAR)[
        : shape[0], : shape[1]]


def _wall(region: np.ndarray, chart: Chart, texel_per_tile: int, px_per_m: float,
          rng: np.random.Generator) -> None:
    """Dirt or moss at the base of an upright face, and posters or signs on a large one."""
    z = chart.positions(texel_per_tile)[..., 2]
    if float(z.min()) < BASE_GROWTH_M[1]:
        top = rng.uniform(*BASE_GROWTH_M) + 0.15 * value_noise(z.shape, (0.4 * px_per_m,) * 2, rng)
        grow = np.clip((top - z) / 0.12, 0.0, 1.0) * (0.55 + 0.45 * rng.random(z.shape))
        colour = np.array((0.2, 0.3, 0.1) if rng.random() < 0.5 else (0.3, 0.24, 0.15), np.float32)
        mottle = 0.7 + 0.3 * value_noise(z.shape, (0.05 * px_per_m,) * 2, rng)[..., None]
        region[:] = region * (1.0 - grow[..., None]) + grow[..., None] * colour * mottle
    area_m2 = chart.w * chart.h / px_per_m**2
    if chart.w > 2.0 * px_per_m and chart.h > 1.6 * px_per_m:
        for _ in range(min(2, int(rng.poisson(area_m2 / POSTER_AREA_M2)))):
            _poster(region, px_per_m, rng)


def _poster(region: np.ndarray, px_per_m: float, rng: np.random.Generator) -> None:
    """A rectangle of colour with a picture and lines of dark 'text', somewhere on `region`."""
    w, h = int(rng.uniform(0.5, 1.1) * px_per_m), int(rng.uniform(0.6, 1.3) * px_per_m)
    y0 = int(rng.integers(0, max(1, region.shape[0] - h)))
    x0 = int(rng.integers(0, max(1, region.shape[1] - w)))
    poster = np.empty((h, w, 3), np.float32)
    poster[:] = rng.uniform(0.1, 0.95, 3)
    poster[: h // 4] = rng.uniform(0.05, 0.95, 3)
    cells = rng.uniform(0.05, 0.95, (3, 3, 3)).astype(np.float32)
    pic = cv2.resize(cells, (max(1, w // 2), max(1, h // 3)), interpolation=cv2.INTER_NEAREST)
    poster[h // 3: h // 3 + pic.shape[0], w // 4: w // 4 + pic.shape[1]] = pic
    line = max(1, h // 16)
    for row in range(h * 2 // 3 + line, h - line, 2 * line):
        end = int(rng.uniform(0.3, 0.9) * w)
        poster[row:row + line, w // 10:end] *= 0.15
    region[y0:y0 + h, x0:x0 + w] = poster[: region.shape[0] - y0, : region.shape[1] - x0]
