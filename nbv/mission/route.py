"""A plan's views as a route a UAV flies: take-off, ferry, the flown path through the views, ferry home.

Positions are metres east, north and up from the target's footprint centre on
the ground (the plan's scene frame, +x east, +y north, +z up, scaled by
`target_size_m` over the normalised target's largest side); the ground is taken
flat, at the take-off point's height. The legs between views follow the plan's
flown path (`nbv.flight.shell_path`: along the viewing shell, clear of the target and the ground),
sampled every `waypoint_spacing_m`, and never below the safety altitude. Ferries between the take-off
point and the path fly at the safety altitude above the target's top, so a ferry that crosses the
target clears it; with the default take-off point (below the start view, moved out beside the
footprint when the start view looks down from above the roof) the ferry out is a straight climb.
Every view waypoint faces the target (heading to the footprint centre) with the gimbal pitched to
minus the view's elevation.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from nbv.flight import shell_path
from nbv.mission.config import MissionConfig
from nbv.mission.geodesy import heading_deg, latlon_to_enu
from render.viewpoint import Viewpoint

SAME_M = 0.01
"""Positions closer than this (metres) are one waypoint."""

TAKEOFF_CLEARANCE_M = 2.0
"""Least distance (metres) from the target's footprint of the default take-off point."""


@dataclass(frozen=True)
class PlannedViews:
    """What a plan folder says about its flight, in the normalised scene frame."""

    start: Viewpoint
    """Where the UAV starts (plan.json's `start_viewpoint`; the first view in plans that predate it)."""
    views: tuple[Viewpoint, ...]
    """The planned views, in flight order."""
    center: np.ndarray
    """Scene centre the viewpoints are about (the normalised target's bounding-box centre), metres."""
    bounds: np.ndarray
    """(2, 3) corners of the normalised target's bounding box, metres."""
    start_recorded: bool
    """Whether plan.json recorded the start view."""

    @property
    def size_m(self) -> float:
        """The normalised target's largest side (1 m up to rounding)."""
        return float(np.max(self.bounds[1] - self.bounds[0]))


@dataclass(frozen=True)
class Waypoint:
    """One position of the route, metres from the target's footprint centre on the ground."""

    enu: np.ndarray
    """(east, north, up) metres; up is above the take-off ground."""
    kind: str
    """'takeoff' (climb to the safety altitude), 'ferry', 'leg' (on the flown path) or 'view' (a capture)."""
    heading_deg: float | None = None
    """Compass heading to hold, degrees (None: the autopilot's choice, on ferries)."""
    pitch_deg: float | None = None
    """Gimbal pitch for the view this waypoint flies to or is, degrees (negative: down)."""
    view: int | None = None
    """Index of the view captured here ('view' waypoints)."""


@dataclass(frozen=True)
class Route:
    """A whole mission: its waypoints in order, ending above the take-off point before return to launch."""

    waypoints: tuple[Waypoint, ...]
    """Take-off first, then ferry, legs and views, then the ferry home."""
    takeoff_en: tuple[float, float]
    """Take-off point, metres east and north of the target."""
    views: tuple[Waypoint, ...]
    """The view waypoints, one per planned view, in order."""
    scale: float
    """Real metres per normalised metre."""
    ferry_altitude_m: float
    """Altitude of the ferries (the target's top plus the safety altitude), metres."""
    path_m: float
    """Metres of the flown path from the start view to the last view, real scale."""
    start_recorded: bool
    """Whether the route starts at the plan's recorded start view (else at its first view)."""


def read_plan(folder: Path) -> PlannedViews:
    """The start view, the views and the normalised target's bounds of the `nbv plan` folder `folder`.

    Raises:
        FileNotFoundError: plan.json or gt.ply is missing.
        ValueError: either is unreadable, or the viewpoints are malformed.
    """
    folder = Path(folder)
    plan, gt = folder / "plan.json", folder / "gt.ply"
    for file in (plan, gt):
        if not file.is_file():
            raise FileNotFoundError(f"{file} not found: PLAN_DIR must be a folder `nbv plan --out DIR` wrote")
    try:
        doc = json.loads(plan.read_text())
        views = tuple(Viewpoint(*map(float, v)) for v in doc["viewpoints"])
        start = doc.get("start_viewpoint")
        start_view = views[0] if start is None else Viewpoint(*map(float, start))
    except (OSError, ValueError, TypeError, KeyError, IndexError) as err:
        raise ValueError(f"{plan}: not a plan.json with viewpoints [R, azimuth, elevation] "
                         f"({err!r})") from err
    if not views:
        raise ValueError(f"{plan}: the plan has no viewpoints")
    try:
        bounds = np.asarray(trimesh.load(gt, force="mesh", process=False).bounds, dtype=np.float64)
    except (OSError, ValueError, TypeError, AttributeError) as err:
        raise ValueError(f"{gt}: not a readable mesh (the plan's normalised target) ({err!r})") from err
    if bounds.shape != (2, 3) or not np.all(np.isfinite(bounds)) or not np.max(bounds[1] - bounds[0]) > 0:
        raise ValueError(f"{gt}: the plan's normalised target has no extent")
    return PlannedViews(start_view, views, bounds.mean(axis=0), bounds, start is not None)


def plan_route(config: MissionConfig) -> Route:
    """The route flying `config.plan`'s views at the target's real place and size (module docstring).

    Raises:
        ValueError: a view below the safety altitude, or a take-off point inside the target's footprint.
    """
    planned = read_plan(config.plan)
    scale = config.target_size_m / planned.size_m
    path = shell_path(planned.start, planned.views, step_m=config.waypoint_spacing_m / scale)
    points = (path.points + planned.center) * scale
    target_en = planned.center[:2] * scale
    shell = _path_waypoints(points, set(path.leg_ends), planned, target_en, config.safety_altitude_m)
    views = tuple(w for w in shell if w.kind == "view")
    for w in views:
        if w.enu[2] < config.safety_altitude_m:
            raise ValueError(f"view {w.view + 1} of {config.plan} lies {w.enu[2]:.2f} m above the ground, "
                             f"below --safety-altitude-m {config.safety_altitude_m:g}: lower the safety "
                             f"altitude or scale the target up (--target-size-m {config.target_size_m:g})")
    takeoff = _takeoff(config, points[0], planned.bounds * scale)
    ferry = float(planned.bounds[1, 2] * scale + config.safety_altitude_m)
    climb = Waypoint(np.array([*takeoff, config.safety_altitude_m]), "takeoff")
    out, home = _ferry(takeoff, shell[0].enu, ferry), _ferry(takeoff, shell[-1].enu, ferry)[::-1]
    waypoints = [climb, *out, *shell, *home]
    return Route(tuple(waypoints), takeoff, views, scale, ferry, path.total_m * scale, planned.start_recorded)


def _path_waypoints(points: np.ndarray, ends: set[int], planned: PlannedViews, target_en: np.ndarray,
                    floor_m: float) -> list[Waypoint]:
    """Waypoints along the flown path: views at the leg ends, leg points (raised to `floor_m`) between."""
    out: list[Waypoint] = []
    leg = 0
    for i, point in enumerate(points):
        pitch = -math.degrees(planned.views[leg].elevation)  # the view this point flies to
        to_target = target_en - point[:2]
        heading = heading_deg(*to_target) if np.linalg.norm(to_target) > SAME_M else None
        if i in ends:
            here = Waypoint(point.copy(), "view", heading, pitch, leg)
            leg += 1
        else:
            here = Waypoint(np.array([point[0], point[1], max(point[2], floor_m)]), "leg", heading, pitch)
        if out and np.linalg.norm(out[-1].enu - here.enu) < SAME_M and out[-1].kind == "leg":
            out[-1] = here if here.kind == "view" else out[-1]
            continue
        out.append(here)
    return out


def _takeoff(config: MissionConfig, start: np.ndarray, bounds: np.ndarray) -> tuple[float, float]:
    """Take-off point (east, north): the flags' (refused inside the target's footprint), or below the start
    view, moved out along its azimuth to `TAKEOFF_CLEARANCE_M` beyond the footprint if it lies within."""
    if config.takeoff_lat is None:
        return _outside_footprint(start[:2], bounds)
    east, north = latlon_to_enu(config.takeoff_lat, config.takeoff_lon, config.lat, config.lon)
    if _inside(np.array([east, north]), bounds, 0.0):
        raise ValueError(f"--takeoff-lat/--takeoff-lon lie {east:.1f} m east, {north:.1f} m north of the "
                         "target, inside its footprint: take off outside the building")
    return east, north


def _inside(point: np.ndarray, bounds: np.ndarray, margin_m: float) -> bool:
    """Whether (east, north) `point` lies within `margin_m` of the footprint of the (2, 3) `bounds`."""
    return bool(np.all(point >= bounds[0, :2] - margin_m) and np.all(point <= bounds[1, :2] + margin_m))


def _outside_footprint(point: np.ndarray, bounds: np.ndarray) -> tuple[float, float]:
    """`point`, or if within `TAKEOFF_CLEARANCE_M` of the footprint, the first point outward from the
    footprint's centre through it that is not (straight east if `point` is the centre)."""
    if not _inside(point, bounds, TAKEOFF_CLEARANCE_M):
        return float(point[0]), float(point[1])
    centre = bounds[:, :2].mean(axis=0)
    offset = point - centre
    direction = offset / np.linalg.norm(offset) if np.linalg.norm(offset) > SAME_M else np.array([1.0, 0.0])
    half = (bounds[1, :2] - bounds[0, :2]) / 2 + TAKEOFF_CLEARANCE_M
    with np.errstate(divide="ignore"):
        reach = float(np.min(np.where(np.abs(direction) > 1e-12, half / np.abs(direction), np.inf)))
    out = centre + direction * (reach + SAME_M)
    return float(out[0]), float(out[1])


def _ferry(takeoff: tuple[float, float], end: np.ndarray, altitude_m: float) -> list[Waypoint]:
    """The ferry from above the take-off point to above `end` at `altitude_m` (none if `end` is overhead)."""
    if math.dist(takeoff, end[:2]) < SAME_M:
        return []
    return [Waypoint(np.array([*takeoff, altitude_m]), "ferry"),
            Waypoint(np.array([*end[:2], altitude_m]), "ferry")]
