"""A route as a QGroundControl plan file (JSON, `fileType` "Plan"): a MAVLink mission of SimpleItems.

Items: NAV_TAKEOFF (22) to the safety altitude; per waypoint a NAV_WAYPOINT (16) in
MAV_FRAME_GLOBAL_RELATIVE_ALT (3) with its heading as yaw (param 4); before each leg
DO_GIMBAL_MANAGER_PITCHYAW (1000) pitching the gimbal to minus the coming view's elevation;
after each view's waypoint (held `hold_s`) IMAGE_START_CAPTURE (2000), one image; last
NAV_RETURN_TO_LAUNCH (20). The gimbal command is MAVLink's gimbal protocol v2, which PX4
and ArduPilot (4.3 and later) run in missions; DO_MOUNT_CONTROL (205) is deprecated. It is
sent at the start of each leg so the gimbal has settled when the UAV arrives. NaN
parameters (the autopilot's default) are written as null, as QGroundControl writes them.
"""

from __future__ import annotations

from nbv.mission.geodesy import point_latlon
from nbv.mission.route import Route, Waypoint

NAV_WAYPOINT, NAV_RETURN_TO_LAUNCH, NAV_TAKEOFF = 16, 20, 22
DO_GIMBAL_MANAGER_PITCHYAW, IMAGE_START_CAPTURE = 1000, 2000
FRAME_MISSION, FRAME_GLOBAL_RELATIVE_ALT = 2, 3
MAV_AUTOPILOT_PX4, MAV_TYPE_QUADROTOR = 12, 2
"""MAVLink enum values the plan uses (common.xml)."""

CRUISE_SPEED_M_S, HOVER_SPEED_M_S = 15.0, 5.0
"""QGroundControl's default speeds, used only for its flight-time estimates."""


def plan_document(route: Route, lat: float, lon: float, hold_s: float, ground_amsl_m: float) -> dict:
    """The .plan JSON document of `route` about the target at (`lat`, `lon`)."""
    items: list[dict] = []
    pitch = None
    for waypoint in route.waypoints:
        if waypoint.kind == "takeoff":
            items.append(_nav(NAV_TAKEOFF, waypoint, lat, lon, [0.0, 0.0, 0.0, None]))
            continue
        if waypoint.pitch_deg is not None and waypoint.pitch_deg != pitch:
            pitch = waypoint.pitch_deg
            items.append(_command(DO_GIMBAL_MANAGER_PITCHYAW, [pitch, 0.0, None, None, 0, 0, 0]))
        hold = hold_s if waypoint.kind == "view" else 0.0
        items.append(_nav(NAV_WAYPOINT, waypoint, lat, lon, [hold, 0.0, 0.0, waypoint.heading_deg]))
        if waypoint.kind == "view":
            items.append(_command(IMAGE_START_CAPTURE, [0, 0, 1, waypoint.view + 1, None, None, None]))
    items.append(_command(NAV_RETURN_TO_LAUNCH, [0, 0, 0, 0, 0, 0, 0]))
    for number, item in enumerate(items, start=1):
        item["doJumpId"] = number
    home_lat, home_lon = point_latlon(*route.takeoff_en, lat, lon)
    mission = {"version": 2, "firmwareType": MAV_AUTOPILOT_PX4, "vehicleType": MAV_TYPE_QUADROTOR,
               "cruiseSpeed": CRUISE_SPEED_M_S, "hoverSpeed": HOVER_SPEED_M_S, "globalPlanAltitudeMode": 1,
               "plannedHomePosition": [home_lat, home_lon, ground_amsl_m], "items": items}
    return {"fileType": "Plan", "version": 1, "groundStation": "nbv", "mission": mission,
            "geoFence": {"circles": [], "polygons": [], "version": 2},
            "rallyPoints": {"points": [], "version": 2}}


def _nav(command: int, waypoint: Waypoint, lat: float, lon: float, head: list) -> dict:
    """A positioned item (take-off, waypoint): params 1-4 `head`, then latitude, longitude, altitude."""
    east, north, up = map(float, waypoint.enu)
    params = [*head, *point_latlon(east, north, lat, lon), up]
    return {"type": "SimpleItem", "command": command, "frame": FRAME_GLOBAL_RELATIVE_ALT, "params": params,
            "autoContinue": True, "Altitude": up, "AltitudeMode": 1, "AMSLAltAboveTerrain": None}


def _command(command: int, params: list) -> dict:
    """An unpositioned item (gimbal, camera, return to launch)."""
    return {"type": "SimpleItem", "command": command, "frame": FRAME_MISSION, "params": params,
            "autoContinue": True}
