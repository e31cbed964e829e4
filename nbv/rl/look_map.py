"""Where the episode has looked from, from the poses flown alone (`EnvConfig.look_map`, beyond the paper).

The privileged teacher (`nbv.rl.expert`) chooses by which surface samples are still unseen; the students
it trained stayed 2 points under it (paper_results/selection/round7), and with blank images their Bag of
Views vector reads "nothing seen yet" at every step. This map is a memory that needs no image: for a
fixed set of directions c (unit normals of a building's faces: `LOOK_AZIMUTHS` azimuths at each of
`LOOK_ELEVATIONS_DEG`, and straight up), the largest max(0, c . d) over the views flown so far, d the
unit direction from the target centre to a view's camera. On a convex building that is how squarely the
episode has faced the side whose outward normal is c (0: never from its half-space, 1: head-on). It
ignores the radius and what the images show; the Bag of Views vector beside it says the latter.
"""

from __future__ import annotations

import math

import numpy as np

from render.viewpoint import Viewpoint

LOOK_AZIMUTHS = 12
"""Azimuths of the map's directions at each elevation: every 30 degrees from 0."""
LOOK_ELEVATIONS_DEG = (0.0, 30.0, 60.0)
"""Elevations of the map's rings of directions (walls, steep and shallow roofs); straight up comes last."""
LOOK_MAP_SIZE = LOOK_AZIMUTHS * len(LOOK_ELEVATIONS_DEG) + 1
"""Values of the map: ring by ring (azimuth 0 first), then straight up."""


def _unit(azimuth: np.ndarray | float, elevation: np.ndarray | float) -> np.ndarray:
    """Unit vectors (..., 3) at `azimuth` and `elevation` (radians; x at azimuth 0, z up)."""
    ce = np.cos(elevation)
    return np.stack(np.broadcast_arrays(ce * np.cos(azimuth), ce * np.sin(azimuth), np.sin(elevation)), -1)


def look_directions() -> np.ndarray:
    """The map's directions c (`LOOK_MAP_SIZE`, 3), in its order."""
    azimuths = np.arange(LOOK_AZIMUTHS) * (2.0 * math.pi / LOOK_AZIMUTHS)
    rings = [_unit(azimuths, math.radians(e)) for e in LOOK_ELEVATIONS_DEG]
    return np.concatenate(rings + [np.array([[0.0, 0.0, 1.0]])])


_DIRECTIONS = look_directions()


def look_of(view: Viewpoint) -> np.ndarray:
    """One view's map (float32, `LOOK_MAP_SIZE`): max(0, c . d) for each direction c."""
    return np.maximum(_DIRECTIONS @ _unit(view.azimuth, view.elevation), 0.0).astype(np.float32)


def look_map(views: list[Viewpoint]) -> np.ndarray:
    """The map after `views` (float32, `LOOK_MAP_SIZE`): each direction's largest value over them; zeros
    for none."""
    return np.max([look_of(v) for v in views], axis=0) if views else np.zeros(LOOK_MAP_SIZE, np.float32)
