"""The path a UAV flies from its start view through its views in order, along the viewing shell.

Each leg interpolates the spherical viewpoint (docs: DESIGN.md section 11) between its two ends:
radius and elevation linearly, azimuth linearly along the shorter arc (at exactly half a turn:
counter-clockwise). A leg therefore stays between its ends' radii and elevations: with the env's ranges
(R >= 1.5 m, elevation >= 5 degrees) it never comes within 1.5 m of the scene centre, so never inside
the normalised target (largest side 1 m, half-diagonal at most 0.87 m), and never below the centre's
height, so never in the ground (z = 0 lies below the centre). A straight chord between far-apart views
would pass through the building. Positions are metres relative to the scene centre, +x east, +y north,
+z up (the world frame of `render.viewpoint`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from render.viewpoint import Viewpoint


@dataclass(frozen=True)
class FlightPath:
    """A flown path: sampled positions and where each leg ends."""

    points: np.ndarray
    """(M, 3) float64 positions, metres relative to the scene centre (+x east, +y north, +z up);
    `points[0]` is the start view."""
    leg_ends: tuple[int, ...]
    """Index into `points` where leg i ends, at view i (leg 0 starts at the start view)."""
    legs_m: tuple[float, ...]
    """Length of each leg, metres: the polyline through its samples (at least its straight chord)."""

    @property
    def total_m(self) -> float:
        """Metres flown, start view to last view."""
        return float(sum(self.legs_m))


def shell_position(radius: float, azimuth: float, elevation: float) -> np.ndarray:
    """Position of a spherical viewpoint relative to the scene centre, metres (+x east, +y north, +z up)."""
    ce = math.cos(elevation)
    return radius * np.array([ce * math.cos(azimuth), ce * math.sin(azimuth), math.sin(elevation)])


def azimuth_step(start: float, end: float) -> float:
    """The shorter signed turn from azimuth `start` to `end`, radians in (-pi, pi], counter-clockwise +."""
    step = math.remainder(end - start, 2.0 * math.pi)
    return math.pi if step == -math.pi else step


def shell_leg(a: Viewpoint, b: Viewpoint, step_m: float) -> np.ndarray:
    """(n, 3) samples of the shell leg from `a` (excluded) to `b` (included), <= `step_m` of arc apart."""
    d_r, d_az, d_el = b.radius - a.radius, azimuth_step(a.azimuth, b.azimuth), b.elevation - a.elevation
    # The speed |dp/dt| is at most |dR| + R_max (|d_az| + |d_el|): n pieces of that bound are each <= step_m.
    bound = abs(d_r) + max(a.radius, b.radius) * (abs(d_az) + abs(d_el))
    count = max(1, math.ceil(bound / step_m))
    t = np.arange(1, count + 1) / count
    return np.stack([shell_position(a.radius + s * d_r, a.azimuth + s * d_az, a.elevation + s * d_el)
                     for s in t])


def shell_path(start: Viewpoint, views: Sequence[Viewpoint], step_m: float = 0.05) -> FlightPath:
    """The path from `start` through `views` in order along the viewing shell, sampled every <= `step_m`.

    Radius and elevation are interpolated linearly, azimuth along the shorter arc, so the path stays
    on or between the views' shells (see the module docstring for why it cannot enter the target).

    Example:
        >>> quarter = shell_path(Viewpoint(2.0, 0.0, 0.0), [Viewpoint(2.0, math.pi / 2, 0.0)])
        >>> round(quarter.total_m, 3), quarter.leg_ends[-1] == len(quarter.points) - 1
        (3.142, True)
    """
    if not (math.isfinite(step_m) and step_m > 0):
        raise ValueError(f"shell_path step_m must be a positive number of metres, got {step_m}")
    pieces = [shell_position(start.radius, start.azimuth, start.elevation)[None]]
    leg_ends, legs_m, previous, end = [], [], start, 0
    for view in views:
        leg = shell_leg(previous, view, step_m)
        chain = np.concatenate([pieces[-1][-1:], leg])
        legs_m.append(float(np.linalg.norm(np.diff(chain, axis=0), axis=1).sum()))
        end += len(leg)
        leg_ends.append(end)
        pieces.append(leg)
        previous = view
    return FlightPath(np.concatenate(pieces), tuple(leg_ends), tuple(legs_m))
