"""Issue 26's acceptance checks over `nbv online` runs, worked by hand; the path spread against geometry."""

from __future__ import annotations

import math

import pytest

from nbv.experiments.online_acceptance import acceptance_checks, acceptance_section
from nbv.flight import pair_spreads_m, path_gap_m
from render.viewpoint import Viewpoint


def run(seed: int, coverage: float, flight_m: float = 9.0, radius: float = 2.0) -> dict:
    return {"seed": seed, "gt": {"coverage": coverage}, "flight_m": flight_m,
            "viewpoints": [[radius, 0.0, 0.0], [2.0, 1.0, 0.3]]}


def planner(a: tuple[float, float], b: tuple[float, float], **kwargs) -> dict[str, list[dict]]:
    """Two buildings' runs of one planner: seeds 0 and 1 on building A, then on building B."""
    return {"A": [run(0, a[0], **kwargs), run(1, a[1], **kwargs)],
            "B": [run(0, b[0], **kwargs), run(1, b[1], **kwargs)]}


def study(planners: dict[str, dict[str, list[dict]]]) -> dict[str, dict[str, list[dict]]]:
    return {scene: {label: runs[scene] for label, runs in planners.items()} for scene in ("A", "B")}


POLICY = {"A": [run(0, 0.80, 12.0), run(1, 0.90, 12.0)],  # 85 on A
          "B": [run(0, 0.90, 12.0, 1.5), run(1, 0.90, 12.0, 1.5)]}  # 90 on B, the first view 0.5 m nearer
BASELINES = {"orbit": planner((0.80, 0.80), (0.86, 0.86)),  # 80 / 86: mean 83
             "orbit2": planner((0.86, 0.86), (0.88, 0.88)),  # mean 87
             "random": planner((0.78, 0.78), (0.86, 0.86), flight_m=30.0)}  # 78 / 86
BLANK = study({"policy-shipped": planner((0.78, 0.82), (0.84, 0.84))})  # 80 / 84: mean 82


def by_check(checks: list[dict]) -> dict[str, dict]:
    return {c["check"].split(",")[0]: c for c in checks}


def test_a_policy_that_passes_every_check_but_random_on_one_building_unless_the_oracle_is_close():
    runs = study({"policy-shipped": POLICY, **BASELINES})
    checks = by_check(acceptance_checks(runs, BLANK, ["policy-shipped"])["policy-shipped"])
    assert checks["mean coverage minus the tuned orbit's"]["value"] == pytest.approx(87.5 - 83.0)
    assert checks["worst building minus the tuned orbit"]["value"] == pytest.approx(4.0)  # B: 90 - 86
    assert checks["metres flown over the tuned orbit's"]["value"] == pytest.approx(12.0 / 9.0)
    assert checks["path spread"]["value"] == pytest.approx(0.25)  # 0.5 m on the first view, 0 on the second
    assert checks["coverage lost with blank images"]["value"] == pytest.approx(87.5 - 82.0)
    assert checks["mean coverage minus the two tuned rings' (orbit2)"]["value"] == pytest.approx(0.5)
    assert checks["mean coverage minus the two tuned rings' (orbit2)"]["passed"] is None
    worst_random = checks["worst building minus random"]
    assert worst_random["value"] == pytest.approx(4.0) and not worst_random["passed"]  # B: 90 - 86 < 5
    assert [name for name, c in checks.items() if c["passed"] is False] == ["worst building minus random"]
    # An oracle only 4.5 points above random on B holds the policy to within 1 point of it there instead.
    runs = study({"policy-shipped": POLICY, **BASELINES, "oracle": planner((0.95, 0.95), (0.905, 0.905))})
    checks = acceptance_checks(runs, BLANK, ["policy-shipped"])
    assert all(c["passed"] is not False for c in checks["policy-shipped"])
    text = "\n".join(acceptance_section(checks, 2))
    assert "| metres flown over the tuned orbit's | <= 1.5x | 1.33x (yes) |" in text
    assert "| path spread, closest pair of buildings, m | >= 0.20 | 0.25 (yes) |" in text
    assert "| **every check** |  | **yes** |" in text


def test_without_the_oracle_a_building_random_views_nearly_cover_is_excused_at_99_percent():
    # Random views cover 97 % of B: any oracle is under 6 points above them (it is at most 100 %), so a
    # policy at 99.2 % is within 1 point of it; at 98.5 % it may not be, so it is held to +5 there.
    high = {**BASELINES, "random": planner((0.78, 0.78), (0.97, 0.97), flight_m=30.0)}
    excused = {"A": POLICY["A"], "B": [run(0, 0.992, 12.0, 1.5), run(1, 0.992, 12.0, 1.5)]}
    check = by_check(acceptance_checks(study({"policy-shipped": excused, **high}), BLANK,
                                       ["policy-shipped"])["policy-shipped"])["worst building minus random"]
    assert check["passed"] and check["value"] == pytest.approx(7.0)  # A alone: 85 - 78
    held = {"A": POLICY["A"], "B": [run(0, 0.985, 12.0, 1.5), run(1, 0.985, 12.0, 1.5)]}
    check = by_check(acceptance_checks(study({"policy-shipped": held, **high}), BLANK,
                                       ["policy-shipped"])["policy-shipped"])["worst building minus random"]
    assert not check["passed"] and check["value"] == pytest.approx(1.5)  # B: 98.5 - 97
    # Where the oracle clause excuses every building, the value is the worst of all and the check passes.
    both = study({"policy-shipped": planner((0.992, 0.992), (0.992, 0.992)), **high,
                  "random": planner((0.97, 0.97), (0.98, 0.98))})
    check = by_check(acceptance_checks(both, BLANK, ["policy-shipped"])["policy-shipped"])[
        "worst building minus random"]
    assert check["passed"] and check["value"] == pytest.approx(1.2)


def test_missing_planners_fail_their_checks_by_name():
    runs = study({"policy-shipped": POLICY, "random": BASELINES["random"]})
    checks = acceptance_checks(runs, None, ["policy-shipped"])
    text = "\n".join(acceptance_section(checks, 2))
    assert "| mean coverage minus the tuned orbit's, points | >= +3.0 | n/a (no) |" in text
    assert "| coverage lost with blank images, points | >= 3.0 | n/a (no) |" in text
    assert "| **every check** |  | **no** |" in text


def test_path_gap_is_the_mean_distance_between_matching_camera_positions():
    a = [Viewpoint(2.0, 0.0, 0.0), Viewpoint(2.0, math.pi / 2, 0.0)]
    b = [Viewpoint(2.0, math.pi, 0.0), Viewpoint(2.0, math.pi / 2, math.pi / 2 - 1e-12)]
    # opposite sides: 4 m; a quarter circle of radius 2 up to the zenith: 2 sqrt(2) m
    assert path_gap_m(a, b) == pytest.approx((4.0 + 2.0 * math.sqrt(2.0)) / 2)
    assert path_gap_m(a, a[:1]) == 0.0  # compared over the common length
    with pytest.raises(ValueError, match="at least one view"):
        path_gap_m([], a)


def test_pair_spreads_average_over_shared_start_views_only():
    ring = [Viewpoint(2.0, 0.0, 0.2)]
    spreads = pair_spreads_m({"A": {0: ring, 1: ring}, "B": {0: [Viewpoint(2.5, 0.0, 0.2)], 1: ring},
                              "C": {1: ring}})
    assert spreads == {("A", "B"): pytest.approx(0.25), ("A", "C"): 0.0, ("B", "C"): 0.0}
    with pytest.raises(ValueError, match="share no start view"):
        pair_spreads_m({"A": {0: ring}, "B": {1: ring}})


def test_a_depth_option_is_held_to_every_check_but_the_blank_images_it_never_reads():
    runs = study({"policy-shipped": POLICY, "lookahead": POLICY, **BASELINES,
                  "oracle": planner((0.95, 0.95), (0.905, 0.905))})
    checks = acceptance_checks(runs, BLANK, ["policy-shipped"], ["lookahead"])
    assert list(checks) == ["policy-shipped", "lookahead"]
    blind = by_check(checks["lookahead"])["coverage lost with blank images"]
    assert blind["value"] is None and blind["passed"] is None  # no bar: it reads no image
    assert [c["value"] for c in checks["lookahead"] if c is not blind] == [
        c["value"] for c in checks["policy-shipped"] if "blank" not in c["check"]]  # the same flights
    text = "\n".join(acceptance_section(checks, 2, ["lookahead"]))
    assert "| check | bar | policy-shipped | lookahead (depth) |" in text
    row = ("| coverage lost with blank images, points | >= 3.0 | +5.5 (yes) "
           "| does not apply (reads no image) |")
    assert row in text
    assert "| **every check** |  | **yes** | **yes** |" in text  # 5 of 5 barred checks for the depth option
