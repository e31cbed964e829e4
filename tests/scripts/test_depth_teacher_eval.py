"""`scripts/depth_teacher_eval.py`'s planner on the test building: it flies the teacher's candidate steps
from the start view, each chosen by the look-ahead on the grid fused from its depth, and a dear enough
flight makes it take the shortest leg."""

from __future__ import annotations

import numpy as np

from nbv.flight.path import shell_path
from nbv.planning.world import PlanningWorld
from nbv.recon.config import OccupancyConfig
from nbv.rl.env import action_to_viewpoint
from nbv.rl.expert import CANDIDATES
from scripts.depth_teacher_eval import DepthTeacherPlanner
from tests.nbv.rl.test_bov_observation import config

GRID = OccupancyConfig(grid_resolution=16, gain_ray_stride=8, integrate_ray_stride=4)


def steps_from(view, env) -> list:
    return [action_to_viewpoint(a, view, env) for a in CANDIDATES]


def test_each_view_is_a_candidate_step_and_an_unknown_side_draws_it_round():
    env = config(action_mode="orbit", relative_step=1 / 6)
    world = PlanningWorld(env, seed=3)
    views = DepthTeacherPlanner(env, GRID, flight=0.0).plan(world, 4)
    assert len(views) == 4 and views[0] == world.start
    for before, after in zip(views, views[1:]):
        assert any(np.allclose(after.as_array(), s.as_array()) for s in steps_from(before, env))
    turned = [abs(np.angle(np.exp(1j * (b.azimuth - a.azimuth)))) for a, b in zip(views, views[1:])]
    assert max(turned) > 0.5  # free flight: it turns to the sides its depth has not seen


def test_a_dear_flight_takes_the_shortest_leg():
    env = config(action_mode="orbit", relative_step=1 / 6)
    world = PlanningWorld(env, seed=3)
    views = DepthTeacherPlanner(env, GRID, flight=1e5).plan(world, 2)
    legs = [shell_path(world.start, [s]).total_m for s in steps_from(world.start, env)]
    assert shell_path(world.start, views[1:]).total_m == min(legs)
