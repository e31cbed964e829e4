"""Fixed orbits, what a pilot flies on a point-of-interest mission: one ring (`orbit`) or two (`orbit2`).

A ring is evenly spaced azimuths at one radius R (metres) and elevation (degrees), flown in the
direction of increasing azimuth from the start view's azimuth, so an orbit starts where every other
planner of the same seed starts (its first view is at the start view's azimuth on the ring, not the
start view itself). Two rings are flown one after the other, in the order given and in the same
direction; the views are split half-half (the first ring takes the odd one: 7 + 6 of 13), and the
second ring's azimuths sit half a step on from the first's, so the two rings' views interleave.

`--planner orbit` and `--planner orbit2` fly the rings chosen on the training buildings by
`scripts/choose_orbit.py` (`SHIPPED_ORBIT`, with the command, commit, resolution and scores they
were chosen on); `orbit:R,ELEVATION` and `orbit2:R1,E1,R2,E2` fly any rings in the allowed ranges.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING

from nbv.planning.base import Planner
from nbv.rl.config import EnvConfig
from render.viewpoint import TWO_PI, Viewpoint

if TYPE_CHECKING:
    from nbv.planning.config import PlanSettings
    from nbv.planning.world import PlanningWorld

SHIPPED_ORBIT = Path(__file__).with_name("shipped") / "orbit.json"
"""The rings chosen on the training buildings ({"rings": {"orbit": [[R, E]], "orbit2": [[R1, E1], [R2,
E2]]}, ...}), written by `scripts/choose_orbit.py`."""


class OrbitSpecError(ValueError):
    """A ring spec that cannot be flown: not numbers, the wrong count, or outside the allowed ranges."""


@dataclass(frozen=True)
class Ring:
    """One orbit ring around the target's centre."""

    radius: float
    """Distance from the target's centre, metres."""
    elevation_deg: float
    """Elevation above the horizontal, degrees."""


def allowed_ranges() -> tuple[tuple[float, float], tuple[float, float]]:
    """The allowed (radius m, elevation deg) ranges of a plan: the env config's defaults (`nbv plan`'s)."""
    default = {f.name: f.default for f in fields(EnvConfig)}
    return ((default["radius_min"], default["radius_max"]),
            (default["elevation_min_deg"], default["elevation_max_deg"]))


def check_ring(ring: Ring, radius: tuple[float, float], elevation: tuple[float, float], where: str) -> Ring:
    """`ring` itself, or an `OrbitSpecError` naming `where` if it lies outside the ranges (m, degrees)."""
    if not (radius[0] <= ring.radius <= radius[1] and elevation[0] <= ring.elevation_deg <= elevation[1]):
        raise OrbitSpecError(
            f"{where}: ring R {ring.radius:g} m, elevation {ring.elevation_deg:g} deg lies outside the "
            f"allowed ranges (R {radius[0]:g}-{radius[1]:g} m, elevation {elevation[0]:g}-{elevation[1]:g} "
            "deg); give a ring inside them")
    return ring


def parse_rings(name: str, argument: str, count: int) -> tuple[Ring, ...]:
    """The `count` rings of a spec's argument ("R,E" per ring, comma-separated), in the allowed ranges."""
    usage = ",".join(f"R{k + 1},E{k + 1}" for k in range(count)) if count > 1 else "R,ELEVATION"
    parts = argument.split(",")
    try:
        numbers = [float(part) for part in parts]
    except ValueError:
        numbers = []
    if len(parts) != 2 * count or len(numbers) != len(parts) or not all(map(math.isfinite, numbers)):
        example = f"{name}:" + ",".join(["1.5,5", "2.0,35"][:count])
        raise OrbitSpecError(f"planner spec {name}:{argument}: need {2 * count} numbers, {name}:{usage} "
                             f"(metres, degrees), e.g. {example}")
    radius, elevation = allowed_ranges()
    rings = (Ring(numbers[k], numbers[k + 1]) for k in range(0, len(numbers), 2))
    return tuple(check_ring(ring, radius, elevation, f"planner spec {name}:{argument}") for ring in rings)


def shipped_rings(name: str, path: Path = SHIPPED_ORBIT) -> tuple[Ring, ...]:
    """The rings of `name` ("orbit" or "orbit2") chosen on the training buildings, read from `path`."""
    if not path.is_file():
        raise FileNotFoundError(f"no shipped orbit choice at {path}; run scripts/choose_orbit.py, or give "
                                f"the rings ({name}:R,ELEVATION,...)")
    rings = json.loads(path.read_text())["rings"][name]
    return tuple(Ring(float(radius), float(elevation)) for radius, elevation in rings)


def split_views(views: int, rings: int) -> list[int]:
    """Views per ring: half-half, the earlier rings taking the odd ones (13 on 2 rings: 7, 6)."""
    return [views // rings + (k < views % rings) for k in range(rings)]


class OrbitPlanner(Planner):
    """Fixed rings flown ring by ring, in the direction of increasing azimuth, from the start azimuth."""

    name = "orbit"

    def __init__(self, rings: tuple[Ring, ...], default_views: int = 13) -> None:
        if not rings:
            raise OrbitSpecError("an orbit needs at least one ring")
        self.rings, self.default_views = tuple(rings), default_views

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """`views` (default 13) viewpoints, split between the rings (`split_views`)."""
        radius = (float(world.low[0]), float(world.high[0]))
        elevation = (math.degrees(world.low[2]), math.degrees(world.high[2]))
        for ring in self.rings:
            check_ring(ring, radius, elevation, f"{self.name} planner")
        chosen = []
        counts = split_views(self.view_count(views), len(self.rings))
        for k, (ring, count) in enumerate(zip(self.rings, counts)):
            offset = k / len(self.rings)  # ring k starts k/len(rings) of its step on: the rings interleave
            chosen += [Viewpoint(ring.radius, world.start.azimuth + TWO_PI * (j + offset) / count,
                                 math.radians(ring.elevation_deg)) for j in range(count)]
        return chosen


def orbit_planner(settings: PlanSettings, seed: int, argument: str | None) -> OrbitPlanner:
    """The registry's `orbit`: the shipped ring, or `orbit:R,ELEVATION`."""
    return OrbitPlanner(parse_rings("orbit", argument, 1) if argument else shipped_rings("orbit"))


def orbit2_planner(settings: PlanSettings, seed: int, argument: str | None) -> OrbitPlanner:
    """The registry's `orbit2`: the shipped two rings, or `orbit2:R1,E1,R2,E2`."""
    planner = OrbitPlanner(parse_rings("orbit2", argument, 2) if argument else shipped_rings("orbit2"))
    planner.name = "orbit2"
    return planner
