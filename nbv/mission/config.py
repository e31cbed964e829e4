"""Settings of `nbv mission`: which plan, where its target stands on Earth, how big it is, how to fly it."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

from tyro.conf import Positional, arg

FORMATS = (".plan", ".kml")
"""Mission file kinds, by the output's extension: a QGroundControl plan, a KML for a map."""

MAX_LATITUDE_DEG = 85.0
"""Largest |latitude| accepted: the local tangent plane (`nbv.mission.geodesy`) degenerates at the poles."""


@dataclass(frozen=True, kw_only=True)
class MissionConfig:
    """Settings of `nbv mission`: a plan folder, the target's place and size on Earth, the flight's safety
    settings and the mission file to write (.plan for QGroundControl, .kml for a map)."""

    plan: Annotated[Path, Positional, arg(metavar="PLAN_DIR")]
    """A folder `nbv plan` wrote: plan.json (the viewpoints and the start view) and gt.ply (the normalised
    target, whose bounds give the scene centre and the 1 m size)."""
    lat: float
    """Latitude of the target (the centre of its footprint on the ground), degrees north (WGS84)."""
    lon: float
    """Longitude of the target, degrees east (WGS84)."""
    target_size_m: float
    """The real target's largest side, metres: the plan's normalised target (largest side 1 m) is scaled
    to it, viewing distances and heights with it."""
    out: Path
    """The mission file to write: FILE.plan (QGroundControl, MAVLink mission) or FILE.kml."""
    takeoff_lat: float | None = None
    """Latitude of the take-off point, degrees; default: below the start view (its ground projection), so
    the UAV climbs straight to where the plan starts."""
    takeoff_lon: float | None = None
    """Longitude of the take-off point, degrees (with --takeoff-lat)."""
    safety_altitude_m: float = 5.0
    """Lowest altitude above the take-off ground of every waypoint after take-off, metres: take-off climbs
    to it, legs never go below it, a view below it is refused; ferries to and from the path fly this high
    above the target's top."""
    waypoint_spacing_m: float = 2.0
    """Most metres between waypoints along a leg: the flown path (along the viewing shell) is sampled at
    this spacing, so the straight hops between samples stay within centimetres of it."""
    hold_s: float = 2.0
    """Seconds the UAV holds at each view (turned to the target, gimbal set) before the capture."""
    ground_amsl_m: float = 0.0
    """Ground altitude above mean sea level at the take-off point, metres: only QGroundControl's planned
    home marker; every waypoint's altitude is relative to home."""
    overwrite: bool = False
    """Replace the output file if it exists."""

    def __post_init__(self) -> None:
        for name in ("lat", "lon", "target_size_m", "safety_altitude_m", "waypoint_spacing_m", "hold_s",
                     "ground_amsl_m"):
            if not math.isfinite(getattr(self, name)):
                flag = "--" + name.replace("_", "-")
                raise ValueError(f"{flag} must be a finite number, got {getattr(self, name)}")
        check_position("--lat/--lon", self.lat, self.lon)
        if (self.takeoff_lat is None) != (self.takeoff_lon is None):
            raise ValueError("give --takeoff-lat and --takeoff-lon together (or neither: take off below the "
                             "start view)")
        if self.takeoff_lat is not None:
            check_position("--takeoff-lat/--takeoff-lon", self.takeoff_lat, self.takeoff_lon)
        if not self.target_size_m > 0:
            raise ValueError(f"--target-size-m must be positive (the real target's largest side in metres), "
                             f"got {self.target_size_m}")
        if self.safety_altitude_m < 0 or not self.waypoint_spacing_m > 0 or self.hold_s < 0:
            raise ValueError("need --safety-altitude-m >= 0, --waypoint-spacing-m > 0 and --hold-s >= 0, got "
                             f"{self.safety_altitude_m}, {self.waypoint_spacing_m}, {self.hold_s}")
        if Path(self.out).suffix.lower() not in FORMATS:
            kind = Path(self.out).suffix or "(none)"
            raise ValueError(f"--out {self.out}: unknown mission format {kind!r}; end the file name in "
                             f"{' or '.join(FORMATS)}")


def check_position(flags: str, lat: float, lon: float) -> None:
    """Refuse a latitude outside +-85 degrees (the tangent plane's limit) or a longitude outside +-180."""
    if not (math.isfinite(lat) and abs(lat) <= MAX_LATITUDE_DEG):
        raise ValueError(f"{flags}: latitude {lat} out of range (degrees north, within "
                         f"+-{MAX_LATITUDE_DEG:g})")
    if not (math.isfinite(lon) and abs(lon) <= 180.0):
        raise ValueError(f"{flags}: longitude {lon} out of range (degrees east, within +-180)")
