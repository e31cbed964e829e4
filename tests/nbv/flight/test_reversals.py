"""Azimuth reversals, counted by hand."""

from __future__ import annotations

import math

from nbv.flight import azimuth_reversals
from render.viewpoint import Viewpoint


def ring(degrees: list[float]) -> list[Viewpoint]:
    return [Viewpoint(2.0, math.radians(d), 0.3) for d in degrees]


def test_an_orbit_through_zero_turns_back_nowhere():
    assert azimuth_reversals(ring([300, 330, 0, 30, 60, 90])) == 0
    assert azimuth_reversals(ring([90, 60, 30, 0, 330])) == 0


def test_a_sweep_turns_back_once_per_turn_and_holds_are_skipped():
    assert azimuth_reversals(ring([0, 40, 80, 40, 0, 40])) == 2
    assert azimuth_reversals(ring([0, 40, 40, 40, 80])) == 0
    assert azimuth_reversals(ring([10, 350, 350, 10])) == 1  # across zero, the short way


def test_fewer_than_three_views_cannot_turn_back():
    assert azimuth_reversals([]) == 0 and azimuth_reversals(ring([0, 170])) == 0
