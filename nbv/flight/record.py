"""A plan's flight as `plan.json` records it, and read back for the plan's first k views.

`plan.json` keeps `start_viewpoint` (R, azimuth, elevation), `flight_m` (metres along the viewing shell
from the start view through every view, `nbv.flight.path.shell_path`), `legs_m` (leg i ends at view i)
and `azimuth_reversals` (counted from the start view). The first k views of a sequential plan fly its
first k legs, so a budget curve reads a prefix's metres from the same record.
"""

from __future__ import annotations

from collections.abc import Sequence

from nbv.flight.path import shell_path
from nbv.flight.reversals import azimuth_reversals
from render.viewpoint import Viewpoint

FLIGHT_FIELDS = ("start_viewpoint", "flight_m", "legs_m", "azimuth_reversals")
"""The keys `flight_record` adds to a plan.json document."""


def flight_record(start: Viewpoint, views: Sequence[Viewpoint]) -> dict:
    """The flight fields (`FLIGHT_FIELDS`) of a plan flying from `start` through `views` in order."""
    path = shell_path(start, views)
    return {"start_viewpoint": start.as_array().tolist(), "flight_m": path.total_m,
            "legs_m": list(path.legs_m), "azimuth_reversals": azimuth_reversals([start, *views])}


def prefix_flight(doc: dict, views: int | None = None) -> dict[str, float]:
    """`flight_m` and `azimuth_reversals` of a plan.json document's first `views` views (all by default).

    Raises:
        ValueError: the document has no flight record (written before plans counted their flight).
    """
    missing = [key for key in FLIGHT_FIELDS if key not in doc]
    if missing:
        raise ValueError(f"plan.json of {doc.get('planner')!r} on {doc.get('scene')!r} has no "
                         f"{', '.join(missing)}: it predates flight records; re-run that plan")
    k = len(doc["legs_m"]) if views is None else views
    if not 0 <= k <= len(doc["legs_m"]):
        raise ValueError(f"plan.json of {doc.get('planner')!r} holds {len(doc['legs_m'])} views, not {k}")
    chosen = [Viewpoint(*v) for v in [doc["start_viewpoint"], *doc["viewpoints"][:k]]]
    return {"flight_m": float(sum(doc["legs_m"][:k])), "azimuth_reversals": azimuth_reversals(chosen)}
