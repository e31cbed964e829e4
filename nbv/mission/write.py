"""`nbv mission`: write a plan's route as a QGroundControl .plan or a KML file, by the output's extension."""

from __future__ import annotations

import json
from pathlib import Path

from common.io import write_text
from nbv.mission.config import MissionConfig
from nbv.mission.kml import kml_document
from nbv.mission.qgc import plan_document
from nbv.mission.route import Route, plan_route


def write_mission(config: MissionConfig) -> Route:
    """Plan the route of `config.plan` and write it to `config.out` atomically; return the route.

    Raises:
        FileExistsError: `out` exists and `overwrite` is off.
    """
    out = Path(config.out)
    if out.exists() and not config.overwrite:
        raise FileExistsError(f"{out} exists: use --overwrite to replace it")
    if not out.parent.is_dir():
        raise FileNotFoundError(f"--out {out}: folder {out.parent} does not exist")
    route = plan_route(config)
    if out.suffix.lower() == ".plan":
        doc = plan_document(route, config.lat, config.lon, config.hold_s, config.ground_amsl_m)
        write_text(out, json.dumps(doc, indent=2, allow_nan=False))
    else:
        write_text(out, kml_document(route, config.lat, config.lon, f"nbv mission: {Path(config.plan).name}"))
    return route


def describe(route: Route, config: MissionConfig) -> str:
    """A few lines on the written mission: views, waypoints, metres, altitudes."""
    top = max(w.enu[2] for w in route.waypoints)
    start = "the plan's start view" if route.start_recorded else "the first view (no start view recorded)"
    return "\n".join([
        f"wrote {config.out}: {len(route.views)} views, {len(route.waypoints)} waypoints "
        f"(scale {route.scale:.3g} m per normalised m)",
        f"flown path {route.path_m:.1f} m from {start}; legs at or above {config.safety_altitude_m:g} m, "
        f"ferries at {route.ferry_altitude_m:.1f} m, highest waypoint {top:.1f} m above the take-off ground"])
