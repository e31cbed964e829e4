"""The shell path against closed forms, and its clearance of a real normalised target and the ground."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nbv.flight import shell_path, shell_position
from render.viewpoint import Viewpoint
from scenes import surface
from scenes.presets import build_preset


def spacing(points: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.diff(points, axis=0), axis=1)


def test_an_azimuth_arc_is_its_circle_s_length_the_short_way_round():
    radius, elevation = 2.0, math.radians(30.0)
    start = Viewpoint(radius, math.radians(350.0), elevation)
    path = shell_path(start, [Viewpoint(radius, math.radians(80.0), elevation)])
    arc = radius * math.cos(elevation) * math.radians(90.0)  # 350 -> 80 degrees counter-clockwise, not 270
    assert path.total_m == pytest.approx(arc, rel=1e-4)
    assert np.allclose(path.points[:, 2], radius * math.sin(elevation))
    assert spacing(path.points).max() <= 0.05 + 1e-12


def test_a_meridian_arc_and_a_radial_leg_match_their_closed_forms():
    up = shell_path(Viewpoint(1.5, 1.0, math.radians(5.0)), [Viewpoint(1.5, 1.0, math.radians(80.0))],
                    step_m=0.02)
    assert up.total_m == pytest.approx(1.5 * math.radians(75.0), rel=1e-4)
    out = shell_path(Viewpoint(1.5, 2.0, 0.3), [Viewpoint(2.5, 2.0, 0.3)])
    assert out.legs_m == pytest.approx((1.0,)) and len(out.points) == 1 + 20


def test_a_half_turn_stays_outside_the_target_and_above_the_ground(monkeypatch):
    monkeypatch.setattr(surface, "texture_path", lambda name, seed: None)  # the geometry without its textures
    scene = build_preset("medieval_tavern")
    low, high = (b - scene.center() for b in scene.bounds())  # the normalised target, about the centre
    ground_z = -scene.center()[2]
    start = Viewpoint(1.5, 0.0, math.radians(5.0))  # the env's lowest, nearest shell
    views = [Viewpoint(1.5, math.pi - 1e-3, math.radians(5.0)), Viewpoint(2.5, 0.2, math.radians(80.0)),
             Viewpoint(1.5, math.pi, math.radians(5.0))]
    path = shell_path(start, views)
    inside = np.all((path.points >= low) & (path.points <= high), axis=1)
    assert not inside.any() and (path.points[:, 2] > ground_z).all()
    # the straight chord of the first leg runs through the building: the path is not that chord
    chord = np.linspace(path.points[0], path.points[path.leg_ends[0]], 101)
    assert np.all((chord >= low) & (chord <= high), axis=1).any()
    assert spacing(path.points).max() <= 0.05 + 1e-12


def test_legs_end_at_their_views_and_are_at_least_the_straight_line():
    rng = np.random.default_rng(0)
    views = [Viewpoint(1.5 + rng.random(), 2 * math.pi * rng.random(), math.radians(5 + 75 * rng.random()))
             for _ in range(14)]
    path = shell_path(views[0], views[1:])
    ends = np.stack([shell_position(*v.as_array()) for v in views])
    assert path.leg_ends[-1] == len(path.points) - 1 and len(path.legs_m) == 13
    assert np.allclose(path.points[[0, *path.leg_ends]], ends)
    straight = np.linalg.norm(np.diff(ends, axis=0), axis=1)
    assert np.all(np.array(path.legs_m) >= straight) and path.total_m == pytest.approx(sum(path.legs_m))
    assert path.total_m > 1.05 * straight.sum()  # far-apart views: the shell is longer than the chords


def test_no_views_is_no_flight_and_a_repeated_view_a_zero_leg():
    start = Viewpoint(2.0, 1.0, 0.5)
    assert shell_path(start, []).total_m == 0.0 and shell_path(start, []).leg_ends == ()
    assert shell_path(start, [start]).legs_m == (0.0,)


@pytest.mark.parametrize("step", [0.0, -1.0, math.nan])
def test_a_bad_step_is_refused_by_name(step):
    with pytest.raises(ValueError, match="step_m must be a positive number"):
        shell_path(Viewpoint(2.0, 0.0, 0.5), [], step_m=step)
