"""Procedural photoreal textures (NumPy), cached on disk as sRGB PNGs keyed by seed.

Each texture is periodic (it tiles without seams) and carries detail at every
scale: per-stone or per-tile colour, mortar and gaps, grain and speckle, so
that SIFT finds keypoints on a rendered facade at any viewing distance.
`TEXTURES` maps a texture name to its generator and to the real-world size (in
metres, before a building is normalised) that one tile of it covers.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from common.cache import cache_file
from common.io import cache_dir
from scenes.noise import anisotropic_fbm, fbm, per_cell, to_uint8, voronoi

TEXTURE_SIZE = 1024
"""Default side of generated textures, pixels."""
_VERSION = 3
"""Bumped whenever a generator changes, so stale cache files are never reused."""

RGB = tuple[float, float, float]
Generator = Callable[[int, np.random.Generator], np.ndarray]


def _grime(size: int, rng: np.random.Generator, amount: float) -> np.ndarray:
    """Multiplicative dirt: low-frequency stains plus fine speckle, (size, size, 1)."""
    stains = 0.6 * fbm(size, rng, beta=2.2, low=2.0) + 0.4 * fbm(size, rng, beta=1.2, low=8.0)
    blotches = fbm(size, rng, beta=1.0, low=12.0, high=64.0)
    patches = fbm(size, rng, beta=0.0, low=3.0, high=10.0)
    speckle = rng.standard_normal((size, size))
    return (1.0 + amount * stains + 0.2 * patches + 0.1 * blotches + 0.06 * speckle)[..., None]


def _blend(a: np.ndarray, b: RGB, weight: np.ndarray) -> np.ndarray:
    return a * (1.0 - weight[..., None]) + np.asarray(b) * weight[..., None]


def brick(base: RGB, mortar: RGB, rows: int = 16, per_row: int = 8) -> Generator:
    """Running-bond bricks with per-brick colour, chipped edges and mortar joints."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        yy, xx = np.mgrid[0:size, 0:size] / size
        row = np.floor(yy * rows).astype(int)
        col_f = (xx * per_row + 0.5 * (row % 2)) % per_row
        ident = row * per_row + col_f.astype(int)
        tint = per_cell(ident, rows * per_row, rng, 3)
        shade = 0.65 + 0.6 * per_cell(ident, rows * per_row, rng)[..., 0]
        color = np.asarray(base) * shade[..., None] * (0.92 + 0.16 * tint)
        fy, fx = (yy * rows) % 1.0, col_f % 1.0
        edge = np.minimum(np.minimum(fy, 1 - fy) * size / rows, np.minimum(fx, 1 - fx) * size / per_row)
        rough = 1.2 * fbm(size, rng, beta=1.0, low=16.0)
        bh = size / rows
        joint = edge + rough < 0.09 * bh
        color = color * (0.8 + 0.2 * np.clip(edge / (0.25 * bh), 0, 1))[..., None]
        color = np.where(
            joint[..., None], np.asarray(mortar) * (0.9 + 0.1 * rng.random((size, size, 1))), color
        )
        return color * _grime(size, rng, 0.12)

    return make


def ashlar(base: RGB, mortar: RGB, rows: int = 6, spread: float = 0.7) -> Generator:
    """Dressed stone blocks of random widths in courses of random heights."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        heights = rng.uniform(0.7, 1.3, rows)
        row_edges = np.concatenate([[0], np.round(np.cumsum(heights) / heights.sum() * size)]).astype(int)
        ident = np.zeros((size, size), dtype=np.int64)
        edge = np.zeros((size, size))
        xx = np.arange(size)
        for r in range(rows):
            lo, hi = row_edges[r], row_edges[r + 1]
            count = int(rng.integers(3, 6))
            widths = rng.uniform(0.6, 1.4, count)
            cuts = np.round(np.cumsum(widths) / widths.sum() * size).astype(int)
            cuts = (cuts + int(rng.integers(0, size))) % size
            cuts = np.sort(cuts)
            col = np.searchsorted(cuts, xx, side="right") % count
            dx = np.min(np.abs(xx[:, None] - np.concatenate([cuts - size, cuts, cuts + size])[None, :]), 1)
            dy = np.minimum(np.arange(hi - lo), np.arange(hi - lo)[::-1])
            ident[lo:hi] = r * 8 + col[None, :]
            edge[lo:hi] = np.minimum(dx[None, :], dy[:, None])
        shade = 1.0 - spread / 2 + spread * per_cell(ident, rows * 8, rng)
        color = np.asarray(base) * shade * (0.95 + 0.1 * per_cell(ident, rows * 8, rng, 3))
        surface = 1.0 + 0.18 * fbm(size, rng, beta=1.4, low=6.0)
        color = color * surface[..., None] * (0.75 + 0.25 * np.clip(edge / 14.0, 0, 1))[..., None]
        joint = edge + 2.0 * fbm(size, rng, beta=1.0, low=24.0) < 4.0
        color = np.where(joint[..., None], np.asarray(mortar)[None, None, :], color)
        return color * _grime(size, rng, 0.12)

    return make


def rubble(base: RGB, mortar: RGB, cells: int = 7, moss: float = 0.0) -> Generator:
    """Irregular field stones (warped Voronoi cells) in mortar, optionally overgrown with moss."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        warp = 0.22 * np.stack([fbm(size, rng, beta=3.0, low=1.0, high=12.0) for _ in range(2)])
        f1, f2, ident = voronoi(size, cells, rng, jitter=0.8, warp=warp)
        gap = f2 - f1
        shade = 0.5 + 0.8 * per_cell(ident, cells * cells, rng)
        color = np.asarray(base) * shade * (0.94 + 0.12 * per_cell(ident, cells * cells, rng, 3))
        color = color * (0.7 + 0.3 * np.clip(gap / 0.25, 0, 1))[..., None]
        color = color * (1.0 + 0.2 * fbm(size, rng, beta=1.2, low=8.0))[..., None]
        color = np.where((gap < 0.07)[..., None], np.asarray(mortar)[None, None, :], color)
        if moss > 0:
            patches = np.clip(fbm(size, rng, beta=2.4, low=2.0) - (1.0 - 2.0 * moss), 0, 1)
            color = _blend(
                color, (0.2, 0.33, 0.1), np.clip(patches * (0.7 + 0.6 * rng.random((size, size))), 0, 1)
            )
        return color * _grime(size, rng, 0.1)

    return make


def plaster(base: RGB, stain: RGB) -> Generator:
    """Lime plaster: uneven trowelled surface, water stains, hairline cracks and speckle."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        f1, f2, _ = voronoi(
            size, 6, rng, warp=0.3 * np.stack([fbm(size, rng, beta=3.0, high=12.0) for _ in range(2)])
        )
        cracks = np.clip(1.0 - (f2 - f1) / 0.02, 0, 1) * (fbm(size, rng, beta=2.0) > 0.6)
        stains = np.clip(
            0.5 * fbm(size, rng, beta=2.0, low=2.0) + 0.2 * fbm(size, rng, beta=1.0, low=12.0), 0, 1
        )
        color = _blend(np.broadcast_to(np.asarray(base), (size, size, 3)).copy(), stain, 0.6 * stains)
        color = color * (1.0 + 0.08 * fbm(size, rng, beta=1.0, low=32.0))[..., None]
        color = color * (1.0 - 0.45 * cracks)[..., None]
        blots = fbm(size, rng, beta=1.6, low=24.0) > 1.8
        color = np.where(blots[..., None], color * 0.8, color)
        return color * _grime(size, rng, 0.08)

    return make


def planks(base: RGB, boards: int = 6, gap: float = 0.05, knots: int = 12) -> Generator:
    """Wooden boards running along v: grain, rings, knots and dark gaps between boards."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        yy, xx = np.mgrid[0:size, 0:size]
        bw = size / boards
        board = (xx * boards) // size
        local = xx - board * bw
        grain = anisotropic_fbm(size, rng, stretch=12.0, beta=1.3)
        rings = np.sin(2 * np.pi * (xx / bw * 3.0 + 0.8 * anisotropic_fbm(size, rng, stretch=6.0, beta=2.0)))
        shade = 0.7 + 0.5 * per_cell(board, boards, rng)[..., 0]
        color = np.asarray(base) * (shade * (1.0 + 0.12 * grain + 0.08 * rings))[..., None]
        for _ in range(knots):
            ky, kx = rng.integers(0, size, 2)
            radius = rng.uniform(6, 16)
            d = np.hypot(
                ((yy - ky + size // 2) % size - size // 2) / 1.8, (xx - kx + size // 2) % size - size // 2
            )
            color = color * (1.0 - 0.5 * np.clip(1.0 - d / radius, 0, 1))[..., None]
        seam = np.minimum(local, bw - 1 - local) < gap * bw / 2
        color = np.where(seam[..., None], color * 0.3, color)
        return color * _grime(size, rng, 0.08)

    return make


def tiles(
    base: RGB, rows: int = 16, per_row: int = 16, spread: float = 0.6, round_edge: bool = True
) -> Generator:
    """Overlapping roof tiles (or slates): staggered rows, shadowed lower edges, colour per tile."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        yy, xx = np.mgrid[0:size, 0:size] / size
        row = np.floor(yy * rows).astype(int)
        col_f = (xx * per_row + 0.5 * (row % 2)) % per_row
        ident = row * per_row + col_f.astype(int)
        u, v = col_f % 1.0, (yy * rows) % 1.0
        shade = 1.0 - spread / 2 + spread * per_cell(ident, rows * per_row, rng)
        color = np.asarray(base) * shade * (0.95 + 0.1 * per_cell(ident, rows * per_row, rng, 3))
        bulge = np.sin(np.pi * u) if round_edge else np.ones_like(u)
        color = color * (0.7 + 0.4 * bulge * (1.0 - 0.5 * v))[..., None]
        lip = v > 0.82 - (0.12 * (1 - bulge) if round_edge else 0.0)
        color = np.where(lip[..., None], color * 0.35, color)
        side = np.minimum(u, 1 - u) * size / per_row < 2
        color = np.where(side[..., None], color * 0.5, color)
        color = color * (1.0 + 0.22 * fbm(size, rng, beta=1.2, low=3.0, high=48.0))[..., None]
        lichen = np.clip(fbm(size, rng, beta=2.0, low=4.0) - 1.0, 0, 1)
        color = _blend(color, (0.55, 0.55, 0.4), 0.6 * lichen)
        return color * _grime(size, rng, 0.1)

    return make


def foliage(base: RGB, dry: RGB) -> Generator:
    """Grass: vertical blades (stretched noise), patches of dry grass and dark clumps."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        blades = anisotropic_fbm(size, rng, stretch=6.0, beta=0.8)
        patches = np.clip(0.5 + 0.4 * fbm(size, rng, beta=2.2, low=2.0), 0, 1)
        color = _blend(np.broadcast_to(np.asarray(base), (size, size, 3)).copy(), dry, patches)
        color = color * (1.0 + 0.35 * blades)[..., None]
        clumps = fbm(size, rng, beta=1.4, low=16.0) > 1.4
        return np.where(clumps[..., None], color * 0.55, color) * _grime(size, rng, 0.1)

    return make


def pebbles(base: RGB, cells: int = 40) -> Generator:
    """Gravel: rounded pebbles of varied tone with dark gaps."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        f1, f2, ident = voronoi(size, cells, rng, jitter=0.9)
        shade = 0.5 + 0.8 * per_cell(ident, cells * cells, rng)
        color = np.asarray(base) * shade * (0.94 + 0.12 * per_cell(ident, cells * cells, rng, 3))
        color = color * (1.1 - 0.5 * np.clip(f1, 0, 1))[..., None]
        return np.where(((f2 - f1) < 0.08)[..., None], color * 0.35, color) * _grime(size, rng, 0.1)

    return make


def glass(base: RGB) -> Generator:
    """Window glass: dark panes with sky reflections and streaks."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        reflect = np.clip(0.5 + 0.35 * fbm(size, rng, beta=2.4, low=1.0), 0, 1)
        streaks = anisotropic_fbm(size, rng, stretch=0.15, beta=1.2)
        color = np.asarray(base) * (0.6 + 0.9 * reflect + 0.15 * streaks)[..., None]
        return color * _grime(size, rng, 0.05)

    return make


def paint(base: RGB, wear: RGB) -> Generator:
    """Painted or lacquered wood: a flat colour worn through to `wear` in patches, with grain."""

    def make(size: int, rng: np.random.Generator) -> np.ndarray:
        worn = np.clip(fbm(size, rng, beta=1.8, low=4.0) - 0.9, 0, 1)
        grain = anisotropic_fbm(size, rng, stretch=10.0, beta=1.2)
        color = _blend(
            np.broadcast_to(np.asarray(base), (size, size, 3)).copy(), wear, np.clip(worn * 1.5, 0, 1)
        )
        return color * (1.0 + 0.1 * grain)[..., None] * _grime(size, rng, 0.08)

    return make


@dataclass(frozen=True)
class TextureKind:
    """A named texture: its generator and the real-world size of one tile."""

    make: Generator
    """(size, rng) -> (size, size, 3) float sRGB image."""
    tile_m: float
    """Metres of surface (before normalisation) that one texture tile covers."""


TEXTURES: dict[str, TextureKind] = {
    "brick_red": TextureKind(brick((0.55, 0.24, 0.16), (0.72, 0.7, 0.64)), 1.6),
    "brick_yellow": TextureKind(brick((0.72, 0.6, 0.38), (0.5, 0.48, 0.44)), 1.6),
    "stone_ashlar": TextureKind(ashlar((0.62, 0.6, 0.55), (0.42, 0.4, 0.37)), 2.4),
    "stone_sandstone": TextureKind(ashlar((0.74, 0.62, 0.45), (0.5, 0.44, 0.36), rows=5), 2.4),
    "stone_rubble": TextureKind(rubble((0.55, 0.52, 0.47), (0.36, 0.34, 0.3)), 2.4),
    "stone_mossy": TextureKind(rubble((0.5, 0.5, 0.46), (0.28, 0.28, 0.24), moss=0.45), 2.4),
    "plaster_white": TextureKind(plaster((0.86, 0.83, 0.76), (0.6, 0.55, 0.45)), 2.0),
    "plaster_ochre": TextureKind(plaster((0.82, 0.66, 0.4), (0.55, 0.42, 0.28)), 2.0),
    "timber_dark": TextureKind(planks((0.3, 0.19, 0.11), boards=3, knots=6), 0.6),
    "timber_planks": TextureKind(planks((0.55, 0.36, 0.2)), 1.2),
    "timber_grey": TextureKind(planks((0.45, 0.42, 0.38), boards=8), 1.6),
    "roof_tiles_red": TextureKind(tiles((0.62, 0.28, 0.17)), 3.0),
    "roof_slate": TextureKind(tiles((0.32, 0.34, 0.37), spread=0.7, round_edge=False), 3.0),
    "roof_shingles": TextureKind(tiles((0.42, 0.33, 0.25), per_row=20, spread=0.6, round_edge=False), 2.6),
    "roof_glazed": TextureKind(tiles((0.2, 0.45, 0.35), rows=12, per_row=24, spread=0.5), 3.0),
    "lacquer_red": TextureKind(paint((0.6, 0.1, 0.07), (0.35, 0.2, 0.12)), 1.0),
    "paint_green": TextureKind(paint((0.18, 0.4, 0.25), (0.45, 0.35, 0.22)), 1.0),
    "paint_blue": TextureKind(paint((0.2, 0.3, 0.5), (0.5, 0.45, 0.38)), 1.0),
    "glass": TextureKind(glass((0.14, 0.18, 0.22)), 1.5),
    "grass": TextureKind(foliage((0.25, 0.42, 0.14), (0.55, 0.5, 0.25)), 2.0),
    "forest_floor": TextureKind(foliage((0.2, 0.3, 0.12), (0.38, 0.28, 0.16)), 2.0),
    "gravel": TextureKind(pebbles((0.6, 0.57, 0.52)), 1.0),
}
"""Every texture the generator knows, by name."""


def make_texture(name: str, seed: int, size: int = TEXTURE_SIZE) -> np.ndarray:
    """The texture `name` for `seed` as a (size, size, 3) uint8 sRGB image (not cached)."""
    if name not in TEXTURES:
        raise ValueError(f"unknown texture {name!r}; known: {', '.join(sorted(TEXTURES))}")
    rng = np.random.default_rng([seed, zlib.crc32(name.encode())])
    return to_uint8(TEXTURES[name].make(size, rng))


def texture_path(name: str, seed: int, size: int = TEXTURE_SIZE) -> Path:
    """The cached PNG of texture `name` for `seed`, generated and written if missing (`common.cache`: where
    the cache cannot keep it, a warning and a copy in this run's temporary folder)."""
    path = cache_dir() / "textures" / f"{name}_s{seed}_{size}px_v{_VERSION}.png"
    return cache_file(path, lambda tmp: Image.fromarray(make_texture(name, seed, size)).save(tmp))
