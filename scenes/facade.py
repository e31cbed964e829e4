"""Facade details with real relief, placed on a `WallFrame` (metres, before normalising).

Openings are cut first (`cut_opening`), for every window and door of the
building, so that the cut also clears any beam or band crossing it; the
fittings (glass, mullions, sills, shutters, door leaves, balconies) are added
afterwards. Material roles used here: reveal, glass, trim, shutters, door,
beams, balcony.
"""

from __future__ import annotations

from dataclasses import dataclass

import manifold3d as mf
import numpy as np

from scenes.csg import SolidBuilder
from scenes.solids import WallFrame, hull

RECESS_M = 0.14
"""How far glass and door leaves sit behind the wall face."""


@dataclass(frozen=True)
class Opening:
    """A window or door: centre `u` along its wall, spanning z0..z1 (absolute heights)."""

    frame: WallFrame
    """The wall it pierces."""
    u: float
    """Centre along the wall, metres from the wall's start."""
    width: float
    """Width of the opening."""
    z0: float
    """Bottom of the opening."""
    z1: float
    """Top of the opening."""
    door: bool = False
    """A door (planked leaf, frame) rather than a window (glass, mullions, sill)."""
    shutters: bool = False
    """Add a pair of battened shutters beside it (windows only)."""
    reach: float = 0.1
    """How far in front of the wall the opening cut reaches (clears beams, bands, plinths)."""


def _z(opening: Opening, z0: float, z1: float) -> tuple[float, float]:
    """Heights relative to the frame origin."""
    base = float(opening.frame.origin[2])
    return z0 - base, z1 - base


def cut_opening(builder: SolidBuilder, o: Opening) -> None:
    """Cut the opening's recess into everything built so far (its sides get the `reveal` role)."""
    half = o.width / 2
    builder.cut(
        o.frame.box((o.u - half, o.u + half), (-RECESS_M - 0.05, o.reach), _z(o, o.z0, o.z1)), "reveal"
    )


def fit_opening(builder: SolidBuilder, o: Opening) -> None:
    """Add the glass or door leaf, frame, mullions, sill, lintel and shutters of an opening."""
    f, half, u = o.frame, o.width / 2, o.u
    back = (-RECESS_M - 0.3, -RECESS_M)
    if o.door:
        builder.add(f.box((u - half - 0.01, u + half + 0.01), back, _z(o, o.z0 - 0.01, o.z1 + 0.01)), "door")
        for k in range(1, 4):
            zc = o.z0 + k * (o.z1 - o.z0) / 4
            builder.add(
                f.box(
                    (u - half + 0.05, u + half - 0.05),
                    (-RECESS_M - 0.01, -RECESS_M + 0.04),
                    _z(o, zc - 0.05, zc + 0.05),
                ),
                "door",
            )
        for side in (-1, 1):
            builder.add(
                f.box(_span(u + side * (half + 0.06), 0.12), (-0.02, 0.07), _z(o, o.z0, o.z1 + 0.12)), "trim"
            )
        builder.add(
            f.box((u - half - 0.12, u + half + 0.12), (-0.02, 0.09), _z(o, o.z1, o.z1 + 0.16)), "trim"
        )
        return
    builder.add(f.box((u - half - 0.01, u + half + 0.01), back, _z(o, o.z0 - 0.01, o.z1 + 0.01)), "glass")
    mullion = (-RECESS_M - 0.01, -RECESS_M + 0.05)
    for k in (1, 2):
        builder.add(f.box(_span(u - half + k * o.width / 3, 0.06), mullion, _z(o, o.z0, o.z1)), "trim")
    for t in (0.36, 0.68):
        zm = o.z0 + t * (o.z1 - o.z0)
        builder.add(f.box((u - half, u + half), mullion, _z(o, zm - 0.03, zm + 0.03)), "trim")
    builder.add(f.box((u - half - 0.1, u + half + 0.1), (-RECESS_M, 0.1), _z(o, o.z0 - 0.09, o.z0)), "trim")
    builder.add(f.box((u - half - 0.08, u + half + 0.08), (-0.02, 0.06), _z(o, o.z1, o.z1 + 0.14)), "trim")
    if o.shutters:
        for side in (-1, 1):
            inner = u + side * (half + 0.04)
            outer = inner + side * half
            lo, hi = min(inner, outer), max(inner, outer)
            builder.add(f.box((lo, hi), (-0.02, 0.04), _z(o, o.z0, o.z1)), "shutters")
            for k in range(3):
                zc = o.z0 + (k + 0.5) * (o.z1 - o.z0) / 3
                builder.add(
                    f.box((lo + 0.03, hi - 0.03), (0.03, 0.065), _z(o, zc - 0.05, zc + 0.05)), "shutters"
                )


def quoins(builder: SolidBuilder, f: WallFrame, height: float, course: float = 0.32) -> None:
    """Dressed corner stones at both ends of a wall, alternately long and short, 4 cm proud."""
    for k in range(int(height / course)):
        reach = 0.65 if k % 2 else 0.38
        z = (k * course + 0.02, (k + 1) * course - 0.02)
        builder.add(f.box((-0.04, reach), (-0.02, 0.04), z), "quoins")
        builder.add(f.box((f.length - reach, f.length + 0.04), (-0.02, 0.04), z), "quoins")


def _span(center: float, width: float) -> tuple[float, float]:
    return center - width / 2, center + width / 2


def timber_frame(
    builder: SolidBuilder,
    f: WallFrame,
    height: float,
    posts: list[float],
    brace_top: float,
    width: float = 0.2,
) -> None:
    """Half-timbering on one storey of a wall: sill and head beams, posts at `posts`, X braces.

    Braces cross each panel between neighbouring posts from the sill beam up to
    `brace_top` (under the windows). Beams stand 6 cm proud of the wall.
    """
    n = (-0.02, 0.06)
    builder.add(f.box((0.0, f.length), n, (0.0, width)), "beams")
    builder.add(f.box((0.0, f.length), n, (height - width, height)), "beams")
    for p in posts:
        lo = min(max(p - width / 2, 0.0), f.length - width)
        builder.add(f.box((lo, lo + width), n, (0.0, height)), "beams")
    top = min(brace_top, height - width)
    for a, b in zip(posts[:-1], posts[1:]):
        if b - a < 4 * width or top < 3 * width:
            continue
        left, right = a + width / 2, b - width / 2
        builder.add(f.beam((left, width), (right, top), 0.7 * width, n), "beams")
        builder.add(f.beam((right, width), (left, top), 0.7 * width, n), "beams")


def balcony(builder: SolidBuilder, f: WallFrame, u0: float, u1: float, floor_z: float, depth: float) -> None:
    """A cantilevered balcony: slab, brackets and a railing of posts and rails, on the wall's face."""
    z = floor_z - float(f.origin[2])
    builder.add(f.box((u0, u1), (-0.05, depth), (z - 0.18, z)), "balcony")
    for ub in (u0 + 0.1, (u0 + u1) / 2, u1 - 0.1):
        builder.add(f.beam((ub, z - 0.9), (ub, z - 0.1), 0.12, (-0.02, 0.15)), "beams")
        builder.add(_bracket(f, ub, z, depth), "beams")
    rail_h = 0.95
    count = max(2, int(round((u1 - u0) / 0.3)))
    for k in range(count + 1):
        ub = u0 + 0.04 + k * (u1 - u0 - 0.08) / count
        builder.add(f.box(_span(ub, 0.06), (depth - 0.1, depth - 0.04), (z, z + rail_h)), "balcony")
    steps = max(2, int(round((depth - 0.1) / 0.3)))
    for side in (u0 + 0.04, u1 - 0.04):
        for k in range(steps):
            nb = 0.1 + k * (depth - 0.2) / steps
            builder.add(f.box(_span(side, 0.06), (nb, nb + 0.06), (z, z + rail_h)), "balcony")
    for zr in (z + 0.35, z + rail_h - 0.08):
        builder.add(f.box((u0, u1), (depth - 0.12, depth - 0.02), (zr, zr + 0.08)), "balcony")
        for side in (u0, u1 - 0.1):
            builder.add(f.box((side, side + 0.1), (0.0, depth), (zr, zr + 0.08)), "balcony")


def _bracket(f: WallFrame, u: float, z: float, depth: float) -> mf.Manifold:
    """A triangular knee brace under a balcony slab."""
    pts = [
        f.point(uu, nn, zz)
        for uu in (u - 0.05, u + 0.05)
        for (nn, zz) in ((0.0, z - 0.2), (0.0, z - 0.8), (0.75 * depth, z - 0.2))
    ]
    return hull(np.array(pts))
