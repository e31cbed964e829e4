"""Local east/north metres to latitude and longitude, and compass headings.

A local tangent plane (equirectangular about the target's LAT, LON) on a sphere of
the IUGG mean Earth radius: a mission spans tens to hundreds of metres, where the
plane's error against a great-circle distance is below a millimetre per 100 m and
the sphere's against WGS84 below 0.6 % of a distance, under consumer GNSS error.
"""

from __future__ import annotations

import math

import numpy as np

EARTH_RADIUS_M = 6_371_008.8
"""Mean Earth radius (IUGG), metres."""


def enu_to_latlon(east_m: np.ndarray, north_m: np.ndarray, lat_deg: float,
                  lon_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude (degrees) of points `east_m`, `north_m` metres from (`lat_deg`, `lon_deg`).

    Example:
        >>> lat, lon = enu_to_latlon(np.array([0.0]), np.array([111.195]), 45.0, 7.0)
        >>> round(float(lat[0]), 6), round(float(lon[0]), 6)
        (45.001, 7.0)
    """
    lat = lat_deg + np.degrees(np.asarray(north_m, dtype=np.float64) / EARTH_RADIUS_M)
    lon = lon_deg + np.degrees(np.asarray(east_m, dtype=np.float64)
                               / (EARTH_RADIUS_M * math.cos(math.radians(lat_deg))))
    return lat, (lon + 180.0) % 360.0 - 180.0


def point_latlon(east_m: float, north_m: float, lat_deg: float, lon_deg: float) -> tuple[float, float]:
    """`enu_to_latlon` of one point, as floats."""
    lat, lon = enu_to_latlon(np.array([east_m]), np.array([north_m]), lat_deg, lon_deg)
    return float(lat[0]), float(lon[0])


def latlon_to_enu(lat: float, lon: float, lat_deg: float, lon_deg: float) -> tuple[float, float]:
    """East and north metres of (`lat`, `lon`) from (`lat_deg`, `lon_deg`): `enu_to_latlon`'s inverse."""
    d_lon = (lon - lon_deg + 180.0) % 360.0 - 180.0
    east = math.radians(d_lon) * EARTH_RADIUS_M * math.cos(math.radians(lat_deg))
    return east, math.radians(lat - lat_deg) * EARTH_RADIUS_M


def heading_deg(east_m: float, north_m: float) -> float:
    """Compass heading of the direction (`east_m`, `north_m`): degrees clockwise from north, in [0, 360)."""
    return math.degrees(math.atan2(east_m, north_m)) % 360.0
