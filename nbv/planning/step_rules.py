"""The rules that may rule a look-ahead's step out (`LookaheadOptions.distinct`, `spacing_m`, `sight_deg`;
rounds 24, 29 and 30)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from nbv.flight.path import azimuth_step, shell_position
from render.viewpoint import Viewpoint

if TYPE_CHECKING:
    from nbv.planning.lookahead import LookaheadOptions


def revisits(view: Viewpoint, flown: list[Viewpoint], tolerance: float = 1e-6) -> bool:
    """Whether `view` is one of the views `flown` (radius, azimuth across 2 pi, elevation within
    `tolerance`)."""
    return any(abs(view.radius - f.radius) <= tolerance and abs(view.elevation - f.elevation) <= tolerance
               and abs(azimuth_step(f.azimuth, view.azimuth)) <= tolerance for f in flown)


def crowds(view: Viewpoint, flown: list[Viewpoint], spacing_m: float) -> bool:
    """Whether `view`'s camera lies within `spacing_m` metres (a straight line) of a view `flown`'s."""
    here = shell_position(*view.as_array())
    return any(np.linalg.norm(here - shell_position(*f.as_array())) < spacing_m for f in flown)


def shares_sight(view: Viewpoint, flown: list[Viewpoint], degrees: float) -> bool:
    """Whether `view`'s sight line (the unit direction from the aim point to its camera) lies within
    `degrees` of a view `flown`'s, whatever the radii."""
    here, least = shell_position(1.0, view.azimuth, view.elevation), np.cos(np.radians(degrees))
    return any(np.dot(here, shell_position(1.0, f.azimuth, f.elevation)) > least for f in flown)


def ruled_out(view: Viewpoint, flown: list[Viewpoint], options: LookaheadOptions) -> bool:
    """Whether `options` rule a step to `view` out after the views `flown`: within `spacing_m` of one
    (`crowds`), within `sight_deg` of one's sight line (`shares_sight`), or one of them (`distinct`)."""
    return bool(options.spacing_m and crowds(view, flown, options.spacing_m)) \
        or bool(options.sight_deg and shares_sight(view, flown, options.sight_deg)) \
        or (options.distinct and revisits(view, flown))
