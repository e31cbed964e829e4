"""Missions out: a plan's views as a QGroundControl .plan or a KML for a real UAV (issue 27).

Names are re-exported lazily (`common.lazy`), so importing the config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "MissionConfig": "nbv.mission.config",
    "PlannedViews": "nbv.mission.route",
    "Route": "nbv.mission.route",
    "Waypoint": "nbv.mission.route",
    "plan_route": "nbv.mission.route",
    "read_plan": "nbv.mission.route",
    "write_mission": "nbv.mission.write",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
