"""plan.json's flight record, and its read-back for a plan's first k views."""

from __future__ import annotations

import math

import pytest

from nbv.flight import FLIGHT_FIELDS, flight_record, prefix_flight
from render.viewpoint import Viewpoint


def plan_doc() -> dict:
    start = Viewpoint(2.0, 0.0, 0.0)
    views = [Viewpoint(2.0, math.radians(d), 0.0) for d in (90, 180, 90)]  # on the equator: arcs of R * turn
    return {"planner": "toy", "scene": "none", "viewpoints": [v.as_array().tolist() for v in views],
            **flight_record(start, views)}


def test_the_record_holds_the_legs_their_sum_and_the_turn_backs():
    doc = plan_doc()
    assert set(FLIGHT_FIELDS) <= set(doc)
    assert doc["legs_m"] == pytest.approx([math.pi] * 3, rel=1e-4) and doc["azimuth_reversals"] == 1
    assert doc["flight_m"] == pytest.approx(3 * math.pi, rel=1e-4)


def test_a_prefix_flies_its_first_legs_and_counts_its_own_turn_backs():
    doc = plan_doc()
    assert prefix_flight(doc, 2) == pytest.approx({"flight_m": 2 * math.pi, "azimuth_reversals": 0}, rel=1e-4)
    assert prefix_flight(doc) == pytest.approx({"flight_m": doc["flight_m"], "azimuth_reversals": 1})
    assert prefix_flight(doc, 0) == {"flight_m": 0.0, "azimuth_reversals": 0}


def test_an_old_plan_or_a_budget_it_does_not_hold_is_refused_by_name():
    doc = plan_doc()
    with pytest.raises(ValueError, match="'toy' on 'none' has no flight_m, legs_m: it predates"):
        prefix_flight({k: v for k, v in doc.items() if k not in ("flight_m", "legs_m")})
    with pytest.raises(ValueError, match="holds 3 views, not 4"):
        prefix_flight(doc, 4)
