"""`scripts/selection_frontier.py` on hand-made results: gains (mean and worst building) and metres ratios
against the ring, the first file's figures for a planner scored twice, the counts per group on either axis,
and its files."""

from __future__ import annotations

import json
import sys

import pytest

from scripts import selection_frontier as module


def doc(planners: dict[str, tuple[list[float], list[float], list[float] | None]]) -> dict:
    """A results file: per planner its coverage and metres on buildings a and b, and its blank coverage."""
    def summary(cover, metres, blank):
        out = {"coverage": dict(zip("ab", cover)), "flight_m": dict(zip("ab", metres))}
        return out | ({"blank": dict(zip("ab", blank))} if blank else {})
    return {"results": {name: {"summary": summary(*values)} for name, values in planners.items()}}


RING = ([90.0, 90.0], [8.0, 10.0], None)


def test_points_against_the_ring_and_counts_per_group(tmp_path, monkeypatch):
    first = doc({"orbit": RING, "p": ([94.0, 93.0], [13.0, 13.0], [88.0, 89.0]),
                 "q": ([92.0, 92.0], [12.0, 12.0], [91.0, 92.0])})
    second = doc({"orbit": RING, "p": ([50.0, 50.0], [1.0, 1.0], None),
                  "t": ([95.0, 95.0], [18.0, 18.0], None), "old": ([99.0, 99.0], [9.0, 9.0], None)})
    points = {p["name"]: p for p in module.frontier_points([("g", first), ("teacher", second)], ("old",))}
    assert set(points) == {"orbit", "p", "q", "t"}
    # p: 93.5 against 90 (+3.5), 13 m against 9 (1.44x), 5 points lost blind: inside and looks; the second
    # file's p is not read.
    assert points["p"]["gain"] == pytest.approx(3.5) and points["p"]["ratio"] == pytest.approx(13 / 9)
    assert module.inside(points["p"]) and module.looks(points["p"])
    # q: +2 in 1.33x, 0.5 lost: neither; t: +5 in 2x, no blank flights.
    assert not module.inside(points["q"]) and not module.looks(points["q"])
    assert not module.inside(points["t"]) and points["t"]["drop"] is None
    assert points["orbit"]["group"] == "baseline"
    table = module.report(list(points.values()))
    assert "| g | 2 | 1 | 1 | 1 |" in table and "| teacher | 1 | 0 | 0 | 0 |" in table
    assert "| g | p | +3.50 | +3.00 | 1.44x | 5.0 | yes |" in table  # worst: b, 93 against 90
    (tmp_path / "1.json").write_text(json.dumps(first))
    monkeypatch.setattr(sys, "argv", ["selection_frontier.py", "--results", f"g={tmp_path / '1.json'}",
                                      "--out", str(tmp_path / "out")])
    module.main()
    assert (tmp_path / "out" / "frontier.png").stat().st_size > 0
    assert "| g | 2 | 1 | 1 | 1 |" in (tmp_path / "out" / "frontier.md").read_text()


def test_the_worst_axis_counts_the_worst_building_against_its_bar(tmp_path, monkeypatch):
    # p: +3.5 on the mean but 88.5 on b, 1.5 under the ring: inside on the mean's bar, not the worst's;
    # q: +0.5 on the mean, b 0.5 under the ring: inside on the worst's bar only.
    first = doc({"orbit": RING, "p": ([98.5, 88.5], [12.0, 12.0], [80.0, 80.0]),
                 "q": ([91.5, 89.5], [12.0, 12.0], [80.0, 80.0])})
    points = {p["name"]: p for p in module.frontier_points([("g", first)])}
    assert points["p"]["worst"] == pytest.approx(-1.5) and points["q"]["worst"] == pytest.approx(-0.5)
    assert module.inside(points["p"]) and not module.inside(points["p"], "worst")
    assert not module.inside(points["q"]) and module.inside(points["q"], "worst")
    assert "| g | 2 | 1 | 2 | 1 |" in module.report(list(points.values()), "worst")
    (tmp_path / "1.json").write_text(json.dumps(first))
    monkeypatch.setattr(sys, "argv", ["selection_frontier.py", "--results", f"g={tmp_path / '1.json'}",
                                      "--axis", "worst", "--out", str(tmp_path / "out")])
    module.main()
    text = (tmp_path / "out" / "frontier.md").read_text()
    assert "worst building's coverage over the tuned ring, points at least -1" in text
    assert "--axis worst --out OUT" in text
