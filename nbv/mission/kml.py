"""A route as KML for a map (Google Earth, QGIS): a Placemark per view, the flown path as a LineString.

Each view's Placemark holds its Point and a Camera (heading: compass degrees to the
target; tilt: 0 looks straight down, 90 at the horizon, so 90 minus the view's elevation);
altitudes are relativeToGround, the ground being the take-off point's height.
"""

from __future__ import annotations

from xml.etree import ElementTree as ET

import numpy as np

from nbv.mission.geodesy import enu_to_latlon, point_latlon
from nbv.mission.route import Route

KML_NS = "http://www.opengis.net/kml/2.2"


def kml_document(route: Route, lat: float, lon: float, name: str) -> str:
    """The KML text of `route` about the target at (`lat`, `lon`), titled `name`."""
    ET.register_namespace("", KML_NS)
    root = ET.Element(f"{{{KML_NS}}}kml")
    doc = _sub(root, "Document")
    _sub(doc, "name", name)
    _point(doc, "target", lon, lat, 0.0)
    t_lat, t_lon = point_latlon(*route.takeoff_en, lat, lon)
    _point(doc, "take-off", t_lon, t_lat, 0.0)
    for view in route.views:
        v_lat, v_lon = point_latlon(view.enu[0], view.enu[1], lat, lon)
        pose = (("longitude", v_lon), ("latitude", v_lat), ("altitude", view.enu[2]),
                ("heading", view.heading_deg or 0.0), ("tilt", 90.0 + view.pitch_deg), ("roll", 0.0))
        _point(doc, f"view {view.view + 1}", v_lon, v_lat, float(view.enu[2]), pose)
    enu = np.array([[*route.takeoff_en, 0.0], *(w.enu for w in route.waypoints), [*route.takeoff_en, 0.0]])
    p_lat, p_lon = enu_to_latlon(enu[:, 0], enu[:, 1], lat, lon)
    flown = _sub(doc, "Placemark")
    _sub(flown, "name", "flown path")
    line = _sub(flown, "LineString")
    _sub(line, "altitudeMode", "relativeToGround")
    coordinates = (f"{x:.8f},{y:.8f},{z:.3f}" for x, y, z in zip(p_lon, p_lat, enu[:, 2]))
    _sub(line, "coordinates", " ".join(coordinates))
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def _sub(parent: ET.Element, tag: str, text: str | None = None) -> ET.Element:
    element = ET.SubElement(parent, f"{{{KML_NS}}}{tag}")
    if text is not None:
        element.text = text
    return element


def _point(parent: ET.Element, name: str, lon: float, lat: float, altitude: float,
           camera: tuple[tuple[str, float], ...] = ()) -> ET.Element:
    """A Placemark named `name` with a Point at (`lon`, `lat`, `altitude` above the ground) and, if given,
    a Camera of the `camera` (tag, value) pairs (before the Point, as KML orders a Feature's children)."""
    mark = _sub(parent, "Placemark")
    _sub(mark, "name", name)
    if camera:
        view = _sub(mark, "Camera")
        for tag, value in camera:
            _sub(view, tag, f"{float(value):.8f}")
        _sub(view, "altitudeMode", "relativeToGround")
    point = _sub(mark, "Point")
    _sub(point, "altitudeMode", "relativeToGround")
    _sub(point, "coordinates", f"{lon:.8f},{lat:.8f},{altitude:.3f}")
    return mark
