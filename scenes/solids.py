"""Closed solid primitives (Manifold) placed in world space or on a wall's frame.

A `WallFrame` is the local frame of one straight facade: u runs along the wall,
n points out of it, z is up. Facade details (window recesses, sills, beams,
shutters) are boxes given in (u, n, z) ranges, so that a detail that stands
proud of the wall simply has n > 0 and a recess has n < 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import manifold3d as mf
import numpy as np


def box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> mf.Manifold:
    """An axis-aligned box from corner `lo` to corner `hi` (metres)."""
    size = np.subtract(hi, lo)
    if np.any(size <= 0):
        raise ValueError(f"box has non-positive size {size.tolist()}")
    return mf.Manifold.cube(tuple(size.tolist())).translate(tuple(map(float, lo)))


def hull(points: np.ndarray) -> mf.Manifold:
    """The convex hull of (N, 3) points."""
    return mf.Manifold.hull_points(np.asarray(points, dtype=np.float64))


def prism(polygon: np.ndarray, z0: float, z1: float) -> mf.Manifold:
    """A vertical prism over a counter-clockwise (N, 2) polygon, from z0 to z1."""
    section = mf.CrossSection([np.asarray(polygon, dtype=np.float64)])
    return mf.Manifold.extrude(section, z1 - z0).translate((0.0, 0.0, z0))


def regular_polygon(center: tuple[float, float], radius: float, sides: int, phase: float = 0.0) -> np.ndarray:
    """A counter-clockwise regular polygon, (sides, 2), circumscribed radius `radius`."""
    angles = phase + 2 * np.pi * np.arange(sides) / sides
    return np.stack([center[0] + radius * np.cos(angles), center[1] + radius * np.sin(angles)], 1)


@dataclass(frozen=True)
class WallFrame:
    """The frame of a straight wall: origin at one end of its base line, u along it, n outwards."""

    origin: np.ndarray
    """(3,) world position of the wall's start at floor level."""
    u: np.ndarray
    """(3,) horizontal unit vector along the wall."""
    n: np.ndarray
    """(3,) horizontal unit outward normal."""
    length: float
    """Wall length along u, metres."""

    def point(self, u: float, n: float, z: float) -> np.ndarray:
        """World position of wall coordinates (u, n, z); z is relative to the origin."""
        return self.origin + u * self.u + n * self.n + np.array([0.0, 0.0, z])

    def box(self, u: tuple[float, float], n: tuple[float, float], z: tuple[float, float]) -> mf.Manifold:
        """A box spanning ranges u, n and z in this frame."""
        corners = [self.point(a, b, c) for a in u for b in n for c in z]
        return hull(np.array(corners))

    def beam(
        self, start: tuple[float, float], end: tuple[float, float], width: float, n: tuple[float, float]
    ) -> mf.Manifold:
        """A straight beam of `width` in the wall plane from (u, z) `start` to `end`, spanning n."""
        a, b = np.array(start, float), np.array(end, float)
        axis = (b - a) / np.linalg.norm(b - a)
        side = np.array([-axis[1], axis[0]]) * width / 2
        points = [self.point(uu, nn, zz) for p in (a, b) for (uu, zz) in (p + side, p - side) for nn in n]
        return hull(np.array(points))


def wall_frames(polygon: np.ndarray, z: float) -> list[WallFrame]:
    """One frame per edge of a counter-clockwise (N, 2) footprint polygon, at height z."""
    frames = []
    for i in range(len(polygon)):
        a, b = polygon[i], polygon[(i + 1) % len(polygon)]
        d = b - a
        length = float(np.hypot(*d))
        if length < 1e-9:
            continue
        u = np.array([d[0], d[1], 0.0]) / length
        frames.append(WallFrame(np.array([a[0], a[1], z]), u, np.array([u[1], -u[0], 0.0]), length))
    return frames


def outline(rectangles: list[tuple[float, float, float, float]], grow: float = 0.0) -> list[np.ndarray]:
    """Counter-clockwise outer polygons of the union of (x0, y0, x1, y1) rectangles, grown by `grow`."""
    section = mf.CrossSection(
        [np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float) for x0, y0, x1, y1 in rectangles],
        mf.FillRule.NonZero,
    )
    if grow:
        section = section.offset(grow, mf.JoinType.Miter)
    return [_drop_collinear(np.asarray(p, dtype=np.float64)) for p in section.to_polygons()]


def _drop_collinear(polygon: np.ndarray) -> np.ndarray:
    prev, nxt = np.roll(polygon, 1, axis=0), np.roll(polygon, -1, axis=0)
    a, b = polygon - prev, nxt - polygon
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return polygon[np.abs(cross) > 1e-9 * (1.0 + np.abs(a).sum(1) * np.abs(b).sum(1))]
