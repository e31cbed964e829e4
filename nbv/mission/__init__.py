"""Missions out: a plan's views as a QGroundControl .plan or a KML for a real UAV (issue 27)."""

from nbv.mission.config import MissionConfig
from nbv.mission.route import PlannedViews, Route, Waypoint, plan_route, read_plan
from nbv.mission.write import write_mission

__all__ = ["MissionConfig", "PlannedViews", "Route", "Waypoint", "plan_route", "read_plan", "write_mission"]
