"""The whole-route search (`nbv.planning.route`) on a toy world of three items, worked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from nbv.flight.path import azimuth_step, shell_path
from nbv.planning.lookahead import LookaheadOptions
from nbv.planning.route import STEPS, RouteSearch
from nbv.planning.world import PlanningWorld
from nbv.rl.expert import TIE_BREAK_PER_M
from render.viewpoint import Viewpoint
from tests.nbv.planning.test_lookahead import tiny
from tests.nbv.rl.test_bov_observation import config

START = Viewpoint(2.0, 0.0, np.radians(10.0))
WORTH = np.array([3.0, 2.5, 2.0])
"""X, seen from 10 degrees of elevation anywhere; W, from 40 degrees under 30 degrees of azimuth; V, from 10
degrees at 80 degrees of azimuth or more."""


def step(action: np.ndarray, view: Viewpoint) -> Viewpoint:
    """Forward by 27.7 to 55.4 degrees (action[1]), at 10 to 40 degrees of elevation (action[2]), 2 m out."""
    return Viewpoint(2.0, view.azimuth + (action[1] + 3) / 4 * np.radians(55.4),
                     np.radians(10 + 15 * (action[2] + 1)))


def sees(view: Viewpoint) -> np.ndarray:
    azimuth, elevation = np.degrees(view.azimuth), np.degrees(view.elevation)
    return np.array([elevation < 11, elevation > 39 and azimuth < 30, elevation < 11 and azimuth >= 80])


def search(known: tuple[bool, ...] = (False, False, False), flight: float = 0.0) -> RouteSearch:
    return RouteSearch(START, 2, sees, np.array(known), WORTH, step, flight, 1)


def test_a_route_scores_each_item_once_less_its_flight():
    route = [(0, 0, 0), (0, 4, 0)]  # 27.7 then 83.1 degrees, both at 10: X twice, then V
    views = search(flight=0.5).views(route)
    assert [round(np.degrees(v.azimuth), 1) for v in views] == [27.7, 83.1]
    metres = shell_path(START, views).total_m
    assert metres == pytest.approx(2 * np.cos(np.radians(10)) * np.radians(83.1), rel=1e-3)  # 83.1-degree arc
    assert search(flight=0.5).score(route) == pytest.approx(100 * 5.0 - (0.5 + TIE_BREAK_PER_M) * metres)
    assert search(known=(True, False, False)).score(route) == pytest.approx(100 * 2.0 - TIE_BREAK_PER_M
                                                                            * metres)


def test_greedy_takes_the_most_now_and_the_search_mends_it():
    routes = search()
    greedy = routes.greedy()
    assert greedy == [(0, 0, 0), (0, 4, 0)]  # X first (3 > 2.5, the shortest leg), then V at 83.1 degrees
    assert routes.score(greedy) == pytest.approx(500.0, abs=1e-3)
    best = routes.best()  # W at 27.7 degrees first, the second view (kept at 83.1) sees X and V
    assert best == [(0, 0, 4), (0, 4, 0)] and routes.score(best) == pytest.approx(750.0, abs=1e-3)
    assert routes.improve(best) == best


def test_a_warm_route_is_kept_where_it_scores_more():
    routes = search()
    assert routes.best(warm=[(0, 0, 4), (0, 4, 0)]) == [(0, 0, 4), (0, 4, 0)]
    assert len(STEPS) == 125 and STEPS[0] == (0, 0, 0) and STEPS[-1] == (4, 4, 4)


def test_a_route_has_a_view_to_take():
    with pytest.raises(ValueError, match="at least one view"):
        RouteSearch(START, 0, sees, np.zeros(3, bool), WORTH, step, 0.0, 1)


def test_a_route_flight_steps_forward_and_flies_otherwise_than_the_look_ahead():
    world = PlanningWorld(config(), seed=3)
    routed = tiny(0.0, forward=True, route=True).plan(world, 5)
    advances = np.degrees([azimuth_step(a.azimuth, b.azimuth) for a, b in zip(routed, routed[1:])])
    assert len(routed) == 5 and routed[0] == world.start
    assert np.all((advances > 27.69) & (advances < 55.39))  # 27.7 to 55.4 degrees, never back
    assert routed != tiny(0.0, forward=True).plan(world, 5)
    assert tiny(0.0, forward=True, route=True).plan(world, 5) == routed  # the same grid, the same route


@pytest.mark.parametrize("options", [{}, {"forward": True, "pace": True},
                                     {"forward": True, "distinct": True}])
def test_a_route_plans_forward_steps_alone(options):
    with pytest.raises(ValueError, match="route plans forward steps .forward. and takes neither pace nor"):
        LookaheadOptions(route=True, **options)


def test_restarts_find_a_shorter_sweep_that_one_view_changes_cannot():
    """W known, three views: the greedy route sees X at 34.6 degrees and V at 83.1, then steps 27.7 more.
    A one-view change hands its advance to the next view and the last already takes the shortest step, so
    the search cannot shorten the 110.8-degree sweep; a random start improved sweeps 83.1 (27.7 each), its
    last view at 10 degrees seeing X and V at once."""
    routes = RouteSearch(START, 3, sees, np.array([False, True, False]), WORTH, step, 1.0, 1)
    plain, restarted = routes.best(), routes.best(restarts=8)
    sweep = [round(np.degrees(routes.views(r)[-1].azimuth), 1) for r in (plain, restarted)]
    assert sweep == [110.8, 83.1]
    metres = shell_path(START, routes.views(restarted)).total_m
    assert routes.score(restarted) == pytest.approx(100 * 5.0 - (1.0 + TIE_BREAK_PER_M) * metres)
    assert routes.score(restarted) > routes.score(plain) + 0.5
    assert routes.best(restarts=8) == restarted  # seeded by the views left: a flight repeats itself


@pytest.mark.parametrize("options", [{"restarts": 2, "forward": True}, {"restarts": -1, "forward": True,
                                                                         "route": True}])
def test_restarts_are_a_count_for_a_route(options):
    with pytest.raises(ValueError, match="restarts are a count >= 0 of random routes"):
        LookaheadOptions(**options)
