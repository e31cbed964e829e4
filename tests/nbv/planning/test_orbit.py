"""The fixed orbits: one ring or two from the start view's azimuth, their specs, and the shipped choice."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from nbv.planning.config import PlanSettings
from nbv.planning.orbit import SHIPPED_ORBIT, OrbitPlanner, OrbitSpecError, Ring, shipped_rings, split_views
from nbv.planning.registry import entry, make_planner, planner_label
from render.viewpoint import Viewpoint


def world(start_azimuth: float = 1.0, radius_max: float = 2.5) -> SimpleNamespace:
    """What an orbit reads of a world: the allowed ranges (R m, azimuth, elevation rad), the start view."""
    return SimpleNamespace(low=np.array([1.5, 0.0, math.radians(5)]),
                           high=np.array([radius_max, 2 * math.pi, math.radians(80)]),
                           start=Viewpoint(2.1, start_azimuth, 0.7))


def flat(views: list[Viewpoint]) -> list[float]:
    return [x for v in views for x in (v.radius, v.azimuth, v.elevation)]


def test_orbit_flies_the_hand_worked_ring_from_the_start_azimuth():
    views = OrbitPlanner((Ring(1.75, 10.0),)).plan(world(start_azimuth=5.0), 4)
    e = math.radians(10)  # azimuths 5, 5 + pi/2, 5 + pi, 5 + 3 pi/2, wrapped into [0, 2 pi)
    expected = [1.75, 5.0, e, 1.75, 5.0 - 1.5 * math.pi, e,
                1.75, 5.0 - math.pi, e, 1.75, 5.0 - 0.5 * math.pi, e]
    assert flat(views) == pytest.approx(expected)
    assert len(OrbitPlanner((Ring(2.0, 5.0),)).plan(world(), None)) == 13


def test_two_rings_split_the_views_half_half_and_interleave():
    assert split_views(13, 2) == [7, 6] and split_views(4, 2) == [2, 2] and split_views(1, 2) == [1, 0]
    views = OrbitPlanner((Ring(1.5, 5.0), Ring(2.5, 35.0))).plan(world(start_azimuth=0.5), 5)
    low, high = math.radians(5), math.radians(35)
    step1, step2 = 2 * math.pi / 3, 2 * math.pi / 2  # 3 views on the first ring, then 2 on the second
    assert flat(views) == pytest.approx([1.5, 0.5, low, 1.5, 0.5 + step1, low, 1.5, 0.5 + 2 * step1, low,
                                         2.5, 0.5 + step2 / 2, high, 2.5, 0.5 + 1.5 * step2, high])


def test_specs_name_any_ring_and_label_it_file_safe():
    assert make_planner("orbit:2.25,15", PlanSettings()).rings == (Ring(2.25, 15.0),)
    assert make_planner("orbit2:1.5,5,2,40", PlanSettings()).rings == (Ring(1.5, 5.0), Ring(2.0, 40.0))
    assert entry("orbit:2,5") is entry("orbit") and entry("orbit2:1.5,5,2,40") is entry("orbit2")
    assert planner_label("orbit:2.25,15") == "orbit-2.25_15" and planner_label("orbit") == "orbit"
    assert entry("orbit").spec == "orbit[:R,ELEVATION]" and entry("orbit2").spec == "orbit2[:R1,E1,R2,E2]"


@pytest.mark.parametrize(("spec", "message"), [
    ("orbit:2.0", "need 2 numbers, orbit:R,ELEVATION"),
    ("orbit:2,5,2", "need 2 numbers"),
    ("orbit:two,5", "need 2 numbers"),
    ("orbit:nan,5", "need 2 numbers"),
    ("orbit2:2,5", "need 4 numbers, orbit2:R1,E1,R2,E2"),
    ("orbit:3,5", r"R 3 m, elevation 5 deg lies outside the allowed ranges \(R 1.5-2.5 m"),
    ("orbit:2,85", "elevation 85 deg lies outside the allowed ranges"),
    ("orbit2:2,5,1,35", "R 1 m, elevation 35 deg lies outside"),
])
def test_a_bad_ring_spec_is_a_named_error(spec, message):
    with pytest.raises(OrbitSpecError, match=message):
        make_planner(spec, PlanSettings())


def test_a_ring_outside_the_worlds_ranges_is_refused_when_planned():
    with pytest.raises(OrbitSpecError, match="orbit planner: ring R 2.4 m"):
        OrbitPlanner((Ring(2.4, 5.0),)).plan(world(radius_max=2.2), 3)


def test_the_shipped_choice_loads_lies_in_the_ranges_and_is_the_best_it_scored():
    doc = json.loads(SHIPPED_ORBIT.read_text())
    assert "+dirty" not in doc["commit"] and "scripts/choose_orbit.py" in doc["command"]
    assert not {"alpine_chalet", "imperial_temple", "random:0", "random:5", "random:10"} & set(doc["scenes"])
    for name, count in (("orbit", 1), ("orbit2", 2)):
        rings = make_planner(name, PlanSettings()).rings
        assert len(rings) == count and rings == shipped_rings(name)
        assert all(1.5 <= r.radius <= 2.5 and 5 <= r.elevation_deg <= 80 for r in rings)
        means = {spec: np.mean(list(per.values())) for spec, per in doc["scores"][name].items()}
        chosen = f"{name}:" + ",".join(f"{r.radius:g},{r.elevation_deg:g}" for r in rings)
        assert means[chosen] == max(means.values())


def test_no_shipped_choice_names_the_command_that_makes_it(tmp_path):
    with pytest.raises(FileNotFoundError, match="run scripts/choose_orbit.py"):
        shipped_rings("orbit", tmp_path / "orbit.json")
