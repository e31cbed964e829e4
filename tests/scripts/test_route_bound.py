"""The route bound (round 42's diagnostic) on a hand-made truth: it flies `lookahead-stereo`'s forward steps,
climbs to the one sample only a view from above sees, and refuses a battery that is no battery."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from nbv.rl.presets import default_preset
from render.viewpoint import Viewpoint
from scripts import route_bound
from scripts.route_bound import RouteBound


class Truth:
    """Two samples: one seen from every view, one only from a camera above 70 degrees of elevation."""

    def seen(self, c2w: np.ndarray) -> np.ndarray:
        position = c2w[:3, 3]
        elevation = np.degrees(np.arcsin(position[2] / np.linalg.norm(position)))
        return np.array([True, elevation > 70])


def world(start: Viewpoint) -> SimpleNamespace:
    target = SimpleNamespace(center=lambda: np.zeros(3))
    return SimpleNamespace(target=target, camera=None, seed=0, start=start, env=default_preset().env)


def test_the_bound_climbs_to_what_only_a_view_from_above_sees_on_forward_steps(monkeypatch):
    monkeypatch.setattr(route_bound, "scene_visibility", lambda target, camera, seed: Truth())
    start = Viewpoint(1.5, 0.0, np.radians(5))
    views = RouteBound().plan(world(start), 5)
    assert len(views) == 5 and views[0] == start
    assert max(np.degrees(v.elevation) for v in views) > 70  # the second sample is seen
    advances = np.degrees(np.diff([v.azimuth for v in views])) % 360
    assert np.all((advances > 27.6) & (advances < 55.5))  # forward, 27.7 to 55.4 degrees a view


def test_a_battery_of_no_metres_is_refused():
    with pytest.raises(ValueError, match="battery is a finite number of metres > 0, got 0"):
        RouteBound(0.0)
