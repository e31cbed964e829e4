"""Roofs as closed solids: gable, hip, flat with parapet, pagoda eave skirts, cones; chimneys.

A pitched roof is a plate of vertical thickness `ROOF_T` whose underside runs
from the wall top out to the eave, so the soffit under the overhang is a real,
visible surface and the part above the building merges into the attic. Rect
tuples are (x0, y0, x1, y1), metres. Roles: roof, gable, trim, chimney.
"""

from __future__ import annotations

import math

import numpy as np

from scenes.csg import SolidBuilder
from scenes.solids import box, hull, prism, regular_polygon

ROOF_T = 0.22
"""Vertical thickness of a roof plate, metres."""

Rect = tuple[float, float, float, float]


def _oriented(points: list[tuple[float, float, float]], along_x: bool) -> np.ndarray:
    """Points given with the ridge along x, swapped to run along y when `along_x` is False."""
    pts = np.array(points, dtype=np.float64)
    return pts if along_x else pts[:, [1, 0, 2]]


def _canonical(rect: Rect, along_x: bool) -> Rect:
    x0, y0, x1, y1 = rect
    return rect if along_x else (y0, x0, y1, x1)


def gable_roof(
    builder: SolidBuilder, rect: Rect, z_top: float, pitch_deg: float, overhang: float, along_x: bool
) -> float:
    """A gable roof over `rect` with its ridge along x (or y); returns the ridge height.

    The triangular gable ends get the `gable` role; the two roof plates overhang
    the eaves by `overhang` and the gable ends by 0.8 of it.
    """
    x0, y0, x1, y1 = _canonical(rect, along_x)
    tan = math.tan(math.radians(pitch_deg))
    ym, half = (y0 + y1) / 2, (y1 - y0) / 2
    z_ridge = z_top + half * tan
    body = [
        (x, y, z)
        for x in (x0, x1)
        for (y, z) in (
            (y0, z_top - 0.5),
            (y1, z_top - 0.5),
            (y1, z_top + 0.05),
            (ym, z_ridge + 0.1),
            (y0, z_top + 0.05),
        )
    ]
    builder.add(hull(_oriented(body, along_x)), "gable")
    ox = 0.8 * overhang
    for side in (-1.0, 1.0):
        y_eave, z_eave = ym + side * (half + overhang), z_top - overhang * tan
        plate = [
            (x, y, z)
            for x in (x0 - ox, x1 + ox)
            for (y, z) in ((y_eave, z_eave), (y_eave, z_eave + ROOF_T), (ym, z_ridge), (ym, z_ridge + ROOF_T))
        ]
        builder.add(hull(_oriented(plate, along_x)), "roof")
    cap = [
        (x, ym + dy, z)
        for x in (x0 - ox, x1 + ox)
        for dy in (-0.14, 0.14)
        for z in (z_ridge + ROOF_T - 0.1, z_ridge + ROOF_T + 0.1)
    ]
    builder.add(hull(_oriented(cap, along_x)), "trim")
    return z_ridge + ROOF_T


def hip_roof(
    builder: SolidBuilder, rect: Rect, z_top: float, pitch_deg: float, overhang: float, role: str = "roof"
) -> float:
    """A hip roof (a pyramid over a square) over `rect`, equal pitch on all sides; returns its top."""
    along_x = rect[2] - rect[0] >= rect[3] - rect[1]
    x0, y0, x1, y1 = _canonical(rect, along_x)
    tan = math.tan(math.radians(pitch_deg))
    ym, half = (y0 + y1) / 2, (y1 - y0) / 2
    z_eave, z_ridge = z_top - overhang * tan, z_top + half * tan
    eave = [
        (x, y, z)
        for x in (x0 - overhang, x1 + overhang)
        for y in (y0 - overhang, y1 + overhang)
        for z in (z_eave, z_eave + ROOF_T)
    ]
    ridge = [(x0 + half, ym, z_ridge + ROOF_T), (x1 - half, ym, z_ridge + ROOF_T)]
    builder.add(hull(_oriented(eave + ridge, along_x)), role)
    return z_ridge + ROOF_T


def eave_skirt(
    builder: SolidBuilder, lower: Rect, upper: Rect, z: float, pitch_deg: float, overhang: float
) -> None:
    """A pagoda eave: a sloping skirt from `lower` grown by `overhang` up onto the `upper` storey at z."""
    tan = math.tan(math.radians(pitch_deg))
    run = overhang + max(upper[0] - lower[0], lower[2] - upper[2], upper[1] - lower[1], lower[3] - upper[3])
    z_eave = z - overhang * tan
    pts = [
        (x, y, zz)
        for x in (lower[0] - overhang, lower[2] + overhang)
        for y in (lower[1] - overhang, lower[3] + overhang)
        for zz in (z_eave, z_eave + ROOF_T)
    ]
    pts += [(x, y, z_eave + run * tan + ROOF_T) for x in (upper[0], upper[2]) for y in (upper[1], upper[3])]
    builder.add(hull(np.array(pts)), "roof")
    fascia = [
        (x, y, zz)
        for x in (lower[0] - overhang - 0.06, lower[2] + overhang + 0.06)
        for y in (lower[1] - overhang - 0.06, lower[3] + overhang + 0.06)
        for zz in (z_eave - 0.12, z_eave + 0.12)
    ]
    builder.add(hull(np.array(fascia)), "trim")
    eave_brackets(builder, _grow(lower, 0.5 * overhang), z_eave)


def eave_brackets(builder: SolidBuilder, rect: Rect, z: float, spacing: float = 1.1) -> None:
    """A row of timber brackets (as in dougong) under an eave, around `rect`, tops at height z."""
    x0, y0, x1, y1 = rect
    for a, b in (((x0, y0), (x1, y0)), ((x1, y0), (x1, y1)), ((x1, y1), (x0, y1)), ((x0, y1), (x0, y0))):
        count = max(1, int(math.hypot(b[0] - a[0], b[1] - a[1]) / spacing))
        for k in range(count):
            t = k / count
            x, y = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
            builder.add(box((x - 0.16, y - 0.16, z - 0.42), (x + 0.16, y + 0.16, z + 0.05)), "beams")
            builder.add(box((x - 0.26, y - 0.26, z - 0.2), (x + 0.26, y + 0.26, z + 0.05)), "beams")


def _grow(rect: Rect, g: float) -> Rect:
    return rect[0] - g, rect[1] - g, rect[2] + g, rect[3] + g


def flat_roof(
    builder: SolidBuilder, polygons: list[np.ndarray], inner: list[np.ndarray], z_top: float
) -> float:
    """A flat roof: a parapet over `polygons` and a sunken deck over `inner`; returns its top."""
    for poly in polygons:
        builder.add(prism(poly, z_top - 0.3, z_top + 0.8), "trim")
    for poly in inner:
        builder.cut(prism(poly, z_top + 0.35, z_top + 1.2), "roof")
    return z_top + 0.8


def cone_roof(
    builder: SolidBuilder,
    center: tuple[float, float],
    radius: float,
    sides: int,
    z_top: float,
    pitch_deg: float,
    overhang: float,
) -> float:
    """A conical roof (matching a `sides`-gon tower) with a finial; returns the finial's top."""
    tan = math.tan(math.radians(pitch_deg))
    r = radius + overhang
    z_eave = z_top - overhang * tan
    ring = regular_polygon(center, r, sides)
    pts = [(x, y, z) for x, y in ring for z in (z_eave, z_eave + ROOF_T)]
    apex = z_eave + ROOF_T + r * tan
    builder.add(hull(np.array(pts + [(center[0], center[1], apex)])), "roof")
    cx, cy = center
    builder.add(box((cx - 0.06, cy - 0.06, apex - 0.4), (cx + 0.06, cy + 0.06, apex + 0.9)), "trim")
    return apex + 0.9


def chimney(builder: SolidBuilder, x: float, y: float, z0: float, z1: float, size: float = 0.6) -> None:
    """A chimney stack rising from inside the roof at (x, y) to z1, with a corbelled cap and pots."""
    h = size / 2
    builder.add(box((x - h, y - h * 0.8, z0), (x + h, y + h * 0.8, z1)), "chimney")
    builder.add(
        box((x - h - 0.08, y - h * 0.8 - 0.08, z1 - 0.25), (x + h + 0.08, y + h * 0.8 + 0.08, z1 - 0.1)),
        "trim",
    )
    builder.add(
        box((x - h - 0.05, y - h * 0.8 - 0.05, z1), (x + h + 0.05, y + h * 0.8 + 0.05, z1 + 0.12)), "trim"
    )
    for dx in (-h / 2, h / 2):
        builder.add(
            box((x + dx - 0.09, y - 0.09, z1 + 0.12), (x + dx + 0.09, y + 0.09, z1 + 0.45)), "chimney"
        )
