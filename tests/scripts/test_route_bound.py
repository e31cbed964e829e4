"""The route bound (round 42's diagnostic) on a hand-made truth: it flies `lookahead-stereo`'s forward steps,
climbs to the one sample only a view from above sees, and refuses a battery that is no battery; the script
names one bound per battery and counts their checks (its flights replaced)."""

from __future__ import annotations

import json
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from nbv.rl.presets import default_preset
from render.viewpoint import Viewpoint
from scripts import looks_eval, route_bound
from scripts.route_bound import RouteBound
from tests.scripts.test_looks_eval import results


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


def test_the_script_names_a_bound_per_battery_and_counts_their_checks(tmp_path, monkeypatch):
    made = results()
    for by_building in made["pol"]["runs"].values():
        by_building["blank"] = {}  # a bound flies no blank images
    made["orbit2"] = made["orbit"]
    flown = {}

    def fly(planners, trained, scenes, seeds, views, work, blank_images):
        flown.update(planners)
        runs = {name: made["pol" if name.startswith("route-bound") else name] for name in planners}
        for doc in runs.values():
            doc["summary"] = looks_eval.summarise(doc["runs"], scenes, seeds)
        return runs

    monkeypatch.setattr(route_bound.looks_eval, "evaluate", fly)  # the module the script imported
    monkeypatch.setattr(route_bound.looks_eval, "refuse_held_out", lambda scenes: None)
    monkeypatch.setattr(sys, "argv", ["route_bound.py", "--battery", "13", "17", "--scenes", "a", "b",
                                      "--seeds", "0", "1", "--out", str(tmp_path / "out"),
                                      "--work", str(tmp_path)])
    route_bound.main()
    assert [flown[n][0].battery_m for n in ("route-bound_b13", "route-bound_b17")] == [13.0, 17.0]
    record = json.loads((tmp_path / "out" / "results.json").read_text())
    assert list(record["checks"]) == ["route-bound_b13", "route-bound_b17"]
    table = (tmp_path / "out" / "results.md").read_text()
    assert "| route-bound_b17 | 93.0 | +2.8 | -0.5 | 13.0 | 0.50 | - | 4/6 |" in table  # no blank check
