"""The `lookahead` planner on the test building: it flies the teacher's orbit steps from the start view, each
chosen by the look-ahead on the grid fused from its depth; a dear enough flight makes it take the shortest
leg; `lookahead:W` sets the weight, bad ones refused by their messages."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from nbv.flight.path import azimuth_step, shell_path
from nbv.planning import lookahead as lookahead_module
from nbv.planning.config import PlanSettings
from nbv.planning.infogain import target_grid
from nbv.planning.lookahead import (
    FORWARD_STEP,
    LOOKAHEAD_FLIGHT,
    STEREO_BASELINE_M,
    STEREO_FLIGHT,
    STEREO_HINGE,
    STEREO_PER_VIEW,
    STEREO_ROUTE,
    STEREO_SIDES,
    STEREO_STEEP,
    STEREO_VOTES,
    LookaheadOptions,
    LookaheadPlanner,
    lookahead_planner,
    side_columns,
    side_items,
    stereo_lookahead_planner,
    stereo_partner,
)
from nbv.planning.registry import make_planner
from nbv.planning.step_rules import crowds, revisits, shares_sight
from nbv.planning.world import PlanningWorld
from nbv.recon.config import OccupancyConfig
from nbv.recon.occupancy import UNKNOWN, OccupancyGrid
from nbv.rl.env import action_to_viewpoint
from nbv.rl.expert import CANDIDATES
from nbv.rl.presets import ORBIT_STEP
from render.camera import UAVCamera, pixel_rays
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from tests.nbv.rl.test_bov_observation import config


def tiny(flight: float = 0.0, depth: str = "camera", blank: bool = False, **options) -> LookaheadPlanner:
    """A look-ahead on a 16-voxel grid casting 8 rays across, its `LookaheadOptions` by keyword."""
    return LookaheadPlanner(flight=flight, grid=16, rays=8, depth=depth, blank_images=blank,
                            options=LookaheadOptions(**options))


def steps_from(view, env, mode="orbit", step=ORBIT_STEP) -> list:
    orbit = replace(env, action_mode=mode, relative_step=step)
    return [action_to_viewpoint(a, view, orbit) for a in CANDIDATES]


def test_each_view_is_an_orbit_step_and_an_unseen_side_draws_it_round():
    env = config()
    world = PlanningWorld(env, seed=3)
    views = LookaheadPlanner(flight=0.0, grid=16, rays=8).plan(world, 4)
    assert len(views) == 4 and views[0] == world.start
    for before, after in zip(views, views[1:]):
        assert any(np.allclose(after.as_array(), s.as_array()) for s in steps_from(before, env))
    turned = [abs(np.angle(np.exp(1j * (b.azimuth - a.azimuth)))) for a, b in zip(views, views[1:])]
    assert max(turned) > 0.5  # free flight: it turns to the sides its depth has not seen


def test_a_dear_flight_takes_the_shortest_leg():
    env = config()
    world = PlanningWorld(env, seed=3)
    views = LookaheadPlanner(flight=1e5, grid=16, rays=8).plan(world, 2)
    legs = [shell_path(world.start, [s]).total_m for s in steps_from(world.start, env)]
    assert shell_path(world.start, views[1:]).total_m == min(legs)


def test_past_its_allowance_a_hinged_flight_takes_the_shortest_leg_and_free_before_it_turns():
    env = config()
    world = PlanningWorld(env, seed=3)
    free = LookaheadPlanner(flight=0.0, grid=16, rays=8).plan(world, 3)
    assert tiny(0.0, allowance_m=1e3, excess=1e5).plan(world, 3) == free
    views = tiny(0.0, allowance_m=0.0, excess=1e5).plan(world, 2)
    legs = [shell_path(world.start, [s]).total_m for s in steps_from(world.start, env)]
    assert shell_path(world.start, views[1:]).total_m == min(legs)
    with pytest.raises(ValueError, match="excess weight and battery a view are finite and >= 0, got 1.0, -2"):
        LookaheadOptions(allowance_m=1.0, excess=-2)


def test_a_battery_that_follows_the_views_grows_past_the_allowance_and_frees_the_flight():
    grows = LookaheadOptions(allowance_m=13.0, battery_per_view_m=1.0)
    assert [grows.battery(v) for v in (5, 13, 20)] == [13.0, 13.0, 20.0]
    assert LookaheadOptions(allowance_m=13.0).battery(20) == 13.0
    world = PlanningWorld(config(), seed=3)
    free = LookaheadPlanner(flight=0.0, grid=16, rays=8).plan(world, 3)
    assert tiny(0.0, allowance_m=0.0, excess=1e5, battery_per_view_m=1e3).plan(world, 3) == free
    assert tiny(0.0, allowance_m=0.0, excess=1e5).plan(world, 3) != free
    with pytest.raises(ValueError, match="battery a view are finite and >= 0, got 0.0, 0.0, -1"):
        LookaheadOptions(battery_per_view_m=-1)


def test_a_paced_battery_spends_an_even_share_a_leg_where_an_unpaced_one_spends_it_first_then_hovers():
    world = PlanningWorld(config(), seed=3)
    free = LookaheadPlanner(flight=0.0, grid=16, rays=8).plan(world, 3)
    assert tiny(0.0, allowance_m=3.0, excess=0.0, pace=True).plan(world, 3) == free  # no hinge: no pace
    first, hover = shell_path(world.start, tiny(0.0, allowance_m=3.0, excess=1e5).plan(world, 3)[1:]).legs_m
    assert first > 1.5 and hover < 1e-9  # the free flight's first leg is 2.06 m: it takes what fits
    paced = shell_path(world.start, tiny(0.0, allowance_m=3.0, excess=1e5, pace=True).plan(world, 3)[1:])
    assert max(paced.legs_m) <= 1.5 and min(paced.legs_m) > 1.2  # 1.25 m each, half the battery a leg
    assert LookaheadOptions(allowance_m=12.0, pace=True).hinge(13, 0) == (1.0, 1.0)  # 12 m over 12 legs
    assert LookaheadOptions(allowance_m=12.0, pace=True).hinge(13, 11) == (12.0, 1.0)
    assert LookaheadOptions(allowance_m=12.0).hinge(13, 0) == (12.0, 0.0)


def test_with_patience_it_gives_up_on_what_it_looked_at_without_measuring():
    world = PlanningWorld(config(), seed=3)  # blank frames: stereo measures nothing, the grid stays unknown
    grid = target_grid(world.target, OccupancyConfig(grid_resolution=16))
    K, width, height, center = world.camera.K, world.camera.width, world.camera.height, world.target.center()

    def reached(view):
        return grid.reached(K, viewpoint_to_c2w(view, center), width, height, round(width / 8))

    overlap = {}
    for patience in (0, 1):
        planner = tiny(0.0, "stereo", True, patience=patience)
        views = planner.plan(world, 2)
        overlap[patience] = np.count_nonzero(reached(views[1]) & reached(world.start))
    assert overlap[1] < overlap[0]  # it turns from what the start view looked at
    with pytest.raises(ValueError, match=r"frontier and patience are counts >= 0 \(0: off\) .* got 0, -1, 3"):
        LookaheadOptions(patience=-1)
    with pytest.raises(ValueError, match="its horizon >= 1, got 0, 0, 0"):
        LookaheadOptions(horizon=0)


def test_next_to_free_sees_only_the_frontier_so_blank_frames_take_the_shortest_leg():
    env = config()
    world = PlanningWorld(env, seed=3)
    legs = [shell_path(world.start, [s]).total_m for s in steps_from(world.start, env)]
    blind = tiny(0.0, "stereo", True, next_to_free=True)
    assert shell_path(world.start, blind.plan(world, 2)[1:]).total_m == min(legs)  # nothing free: no gain
    looking = tiny(0.0, next_to_free=True).plan(world, 2)
    assert shell_path(world.start, looking[1:]).total_m > min(legs)


def test_forward_steps_always_advance_the_azimuth_one_way_and_a_dear_flight_takes_the_least():
    world = PlanningWorld(config(), seed=3)
    views = tiny(0.0, forward=True).plan(world, 5)
    advances = np.degrees([azimuth_step(a.azimuth, b.azimuth) for a, b in zip(views, views[1:])])
    assert np.all((advances > 27.69) & (advances < 55.39))  # 27.7 to 55.4 degrees, never back
    dear = tiny(1e5, forward=True).plan(world, 2)
    forward = steps_from(world.start, world.env, "forward", FORWARD_STEP)
    legs = [shell_path(world.start, [s]).total_m for s in forward]
    assert shell_path(world.start, dear[1:]).total_m == min(legs)
    assert np.degrees(azimuth_step(world.start.azimuth, dear[1].azimuth)) == pytest.approx(360 / 13)


def test_valuing_unmeasured_sides_changes_a_looking_flight_but_not_a_blind_one():
    world = PlanningWorld(config(), seed=3)
    plain = tiny(0.0, forward=True).plan(world, 4)
    assert tiny(0.0, forward=True, sides=0.0).plan(world, 4) == plain
    assert tiny(0.0, forward=True, sides=50.0).plan(world, 4) != plain  # occupied voxels seen from new sides
    blind = tiny(0.0, "stereo", True, forward=True).plan(world, 3)
    assert tiny(0.0, "stereo", True, forward=True, sides=50.0).plan(world, 3) == blind  # nothing measured
    with pytest.raises(ValueError, match="weight of a side never measured is finite and >= 0, its steep band "
                                         "under 90 degrees, its ceiling at most 90 .0: none., its sectors 4 "
                                         "or 8, its bands 1 to 3, got -1"):
        LookaheadOptions(sides=-1)


@pytest.mark.parametrize("option", [{"sectors": 8}, {"bands": 2}, {"bands": 1}, {"steep_deg": 60.0}])
def test_a_sides_option_changes_a_flight_that_values_sides_and_only_that(option):
    world = PlanningWorld(config(), seed=3)
    plain, sides = tiny(0.0, forward=True).plan(world, 4), tiny(0.0, forward=True, sides=50.0).plan(world, 4)
    assert tiny(0.0, forward=True, **option).plan(world, 4) == plain  # no sides valued: no change
    assert tiny(0.0, forward=True, sides=50.0, **option).plan(world, 4) != sides


@pytest.mark.parametrize(("option", "message"), [
    ({"sectors": 6}, "its sectors 4 or 8, its bands 1 to 3, got 0.0, 0.0, 0.0, 6, 3"),
    ({"bands": 0}, "its bands 1 to 3, got 0.0, 0.0, 0.0, 4, 0"),
    ({"steep_deg": 90}, "steep band under 90 degrees, its ceiling at most 90 .0: none., its sectors 4 or "
                        "8, its bands 1 to 3, got 0.0, 90")])
def test_a_sides_option_out_of_range_is_refused(option, message):
    with pytest.raises(ValueError, match=message):
        LookaheadOptions(**option)


def test_fewer_bands_make_a_sectors_vertical_bins_one_side():
    steep = OccupancyGrid(np.zeros(3), np.ones(3), resolution=2, steep_deg=60)  # [steep,] down, level, up
    blind = side_columns(steep, LookaheadOptions(bands=2, steep_measures=False))
    assert blind.tolist() == [[1, 2], [3, 3], [5, 6], [7, 7], [9, 10], [11, 11], [13, 14], [15, 15]]
    assert side_columns(steep, LookaheadOptions(bands=2)).tolist()[:3] == [[0, 0], [1, 2], [3, 3]]
    plain = OccupancyGrid(np.zeros(3), np.ones(3), resolution=2)
    assert side_columns(plain, LookaheadOptions(bands=2)).tolist()[:4] == [[0, 1], [2, 2], [3, 4], [5, 5]]
    assert side_columns(steep, LookaheadOptions(bands=1)).tolist()[:3] == [[0, 0, 0], [1, 2, 3], [4, 4, 4]]
    assert side_columns(plain, LookaheadOptions(bands=1, steep_measures=False)).tolist() == \
        [[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]]
    plain.sides[:] = [1 << 1, 1 << 2, 1 << 0, 0, 0, 0, 0, 0]  # measured level, up, down in quadrant 0
    occupied = np.array([0, 1, 2])
    known, weights = side_items(plain, occupied, np.zeros(8, bool), 0.5,
                                side_columns(plain, LookaheadOptions(bands=2)))
    sides = known[8:].reshape(3, 8)[:, :2]  # quadrant 0's down-or-level side, then its up side
    assert sides.tolist() == [[True, False], [False, True], [True, False]]
    assert weights.tolist() == [1.0] * 8 + [0.5] * 24


def test_a_steep_band_that_measures_no_side_drops_its_bins_and_flies_otherwise():
    grid = OccupancyGrid(np.zeros(3), np.ones(3), resolution=2, steep_deg=60)
    assert side_columns(grid, LookaheadOptions()).ravel().tolist() == list(range(16))
    assert side_columns(grid, LookaheadOptions(steep_measures=False)).ravel().tolist() == \
        [1, 2, 3, 5, 6, 7, 9, 10, 11, 13, 14, 15]  # each quadrant's down, level and up
    plain = OccupancyGrid(np.zeros(3), np.ones(3), resolution=2)
    assert side_columns(plain, LookaheadOptions(steep_measures=False)).ravel().tolist() == list(range(12))
    world = PlanningWorld(config(), seed=3)
    steep = tiny(0.0, forward=True, sides=50.0, steep_deg=60.0).plan(world, 4)
    assert tiny(0.0, forward=True, sides=50.0, steep_deg=60.0, steep_measures=False).plan(world, 4) != steep


def test_crowds_measures_the_straight_line_between_cameras():
    flown = [Viewpoint(1.0, 0.0, 0.0)]
    assert crowds(Viewpoint(1.0, np.pi / 3, 0.0), flown, 1.01)  # a 60-degree chord of a 1 m orbit: 1 m
    assert not crowds(Viewpoint(1.0, np.pi / 3, 0.0), flown, 0.99)
    assert not crowds(Viewpoint(1.0, 0.0, 0.0), [], 1.0)


def test_a_spaced_flight_never_steps_near_a_camera_flown():
    world = PlanningWorld(config(), seed=3)
    dear = tiny(1e5, forward=True).plan(world, 4)
    assert crowds(dear[1], dear[:1], 0.6)  # the shortest forward step lands within 0.6 m
    spaced = tiny(1e5, forward=True, spacing_m=0.6).plan(world, 4)
    assert not any(crowds(view, spaced[:i], 0.6) for i, view in enumerate(spaced) if i)
    with pytest.raises(ValueError, match="spacing is a finite distance >= 0 .* got -0.1, 0.0"):
        LookaheadOptions(spacing_m=-0.1)


def test_shares_sight_measures_the_angle_between_directions_whatever_the_radius():
    top = np.radians(80.0)  # cos(angle) = sin^2(80) + cos^2(80) cos(azimuth apart): 14.1 degrees at 90 apart
    flown = [Viewpoint(1.5, 0.0, top)]
    assert shares_sight(Viewpoint(2.5, np.radians(90.0), top), flown, 15.0)
    assert not shares_sight(Viewpoint(1.5, np.radians(100.0), top), flown, 15.0)  # 15.26 degrees
    assert shares_sight(Viewpoint(2.5, 0.0, top), flown, 0.1)  # further out on the same sight line
    assert not shares_sight(Viewpoint(1.5, 0.0, top), [], 15.0)


def test_a_flight_with_the_sight_rule_never_looks_along_a_sight_line_flown():
    world = PlanningWorld(config(), seed=3)
    dear = tiny(1e5, forward=True).plan(world, 4)
    assert shares_sight(dear[1], dear[:1], 30.0)  # the shortest forward step turns the sight line < 30 deg
    sighted = tiny(1e5, forward=True, sight_deg=30.0).plan(world, 4)
    assert not any(shares_sight(view, sighted[:i], 30.0) for i, view in enumerate(sighted) if i)
    with pytest.raises(ValueError, match="sight rule 0 to 180 degrees .* got 0.0, 180"):
        LookaheadOptions(sight_deg=180)


def test_a_distinct_flight_never_repeats_a_view_where_staying_put_costs_least():
    world = PlanningWorld(config(), seed=3)
    stays = LookaheadPlanner(flight=1e5, grid=16, rays=8).plan(world, 4)
    assert stays[1] == stays[2] == stays[3]  # on the steps' levels, staying put is a step, and free
    views = tiny(1e5, distinct=True).plan(world, 4)
    assert views[1] == stays[1] and not any(revisits(view, views[:i]) for i, view in enumerate(views) if i)
    moves = [shell_path(views[1], [s]).total_m for s in steps_from(views[1], world.env)
             if not revisits(s, views[:2])]
    assert shell_path(views[1], views[2:3]).total_m == pytest.approx(min(moves))  # the shortest move


def test_revisits_matches_views_across_the_azimuth_seam_only():
    seam = [Viewpoint(2.0, 2 * np.pi - 1e-8, 0.3)]
    assert revisits(Viewpoint(2.0, 1e-8, 0.3), seam)
    assert not revisits(Viewpoint(2.0, 1e-3, 0.3), seam)
    assert not revisits(Viewpoint(2.1, 1e-8, 0.3), seam) and not revisits(Viewpoint(2.0, 0.0, 0.31), seam)


def test_the_spec_sets_the_flight_weight_and_refuses_bad_ones():
    assert make_planner("lookahead", PlanSettings()).flight == LOOKAHEAD_FLIGHT
    assert make_planner("lookahead:0.2", PlanSettings()).flight == 0.2
    with pytest.raises(ValueError, match="takes a flight weight a metre, got 'fast'"):
        lookahead_planner(PlanSettings(), 0, "fast")
    with pytest.raises(ValueError, match="finite flight weight >= 0"):
        lookahead_planner(PlanSettings(), 0, "-1")
    battery = make_planner("lookahead-stereo:0.2,20", PlanSettings())
    assert (battery.flight, battery.options.allowance_m, battery.options.excess) == (0.2, 20, STEREO_HINGE[1])
    assert battery.options.battery(30) == 20  # a pilot's battery stays whatever the views
    battery = make_planner("lookahead-stereo:,9.5", PlanSettings())
    assert (battery.flight, battery.options.allowance_m) == (STEREO_FLIGHT, 9.5)
    default = make_planner("lookahead-stereo:0.2", PlanSettings()).options
    assert (default.allowance_m, default.battery(20)) == (STEREO_HINGE[0], 20.0)
    for bad in ("0.1,0", "0.1,-3", "0.1,far", "0.1,inf", "0.1,"):
        with pytest.raises(ValueError, match=f"battery of M > 0 metres before the hinge, got '{bad[4:]}'"):
            stereo_lookahead_planner(PlanSettings(), 0, bad)
    with pytest.raises(ValueError, match="grid >= 1, rays >= 1 and depth from .* got 0.07, 48, 0, 'camera'"):
        LookaheadPlanner(rays=0)
    with pytest.raises(ValueError, match="counts >= 0 .* got -1, 0, 3"):
        LookaheadOptions(frontier=-1)


def test_the_second_frame_is_the_baseline_back_along_the_orbit():
    view = Viewpoint(2.0, 0.1, 0.5)
    partner = stereo_partner(view)
    centre = np.zeros(3)
    chord = viewpoint_to_c2w(view, centre)[:3, 3] - viewpoint_to_c2w(partner, centre)[:3, 3]
    assert np.linalg.norm(chord) == pytest.approx(STEREO_BASELINE_M)
    assert (partner.radius, partner.elevation) == (view.radius, view.elevation)
    assert azimuth_step(view.azimuth, partner.azimuth) < 0  # back: clockwise


@pytest.mark.parametrize("side", ["forward", "up"])
def test_other_second_frames_are_the_baseline_forward_or_up(side):
    view, centre = Viewpoint(2.0, 0.1, 0.5), np.zeros(3)
    partner = stereo_partner(view, side=side)
    chord = viewpoint_to_c2w(view, centre)[:3, 3] - viewpoint_to_c2w(partner, centre)[:3, 3]
    assert np.linalg.norm(chord) == pytest.approx(STEREO_BASELINE_M)
    assert partner.radius == view.radius
    if side == "up":  # up the meridian: same azimuth, higher
        assert partner.azimuth == view.azimuth and partner.elevation > view.elevation
    else:  # the mirror of back
        assert partner.elevation == view.elevation
        assert azimuth_step(view.azimuth, partner.azimuth) == pytest.approx(
            -azimuth_step(view.azimuth, stereo_partner(view).azimuth))


def test_more_second_frames_measure_at_least_as_much():
    known = {}
    for partners in (("back",), ("back", "up")):
        world = PlanningWorld(config(camera=UAVCamera(160, 120), render=RenderSettings(spp=4)), seed=3)
        grid = target_grid(world.target, OccupancyConfig(grid_resolution=16))
        tiny(depth="stereo", partners=partners).measure(world, grid, world.start)
        known[partners] = grid.state != UNKNOWN
    assert known["back", "up"].sum() > known["back",].sum()
    assert np.all(known["back", "up"][known["back",]])  # the first pair's knowledge is kept
    with pytest.raises(ValueError, match="partners are sides from"):
        LookaheadOptions(partners=("down",))
    with pytest.raises(ValueError, match="agree 0 to their number"):
        LookaheadOptions(partners=("back", "up"), agree=3)
    with pytest.raises(ValueError, match="side is one of"):
        stereo_partner(Viewpoint(2.0, 0.1, 0.5), side="left")


def test_fusing_only_what_pairs_agree_on_knows_less_than_every_pair():
    known = {}
    for agree in (0, 2):
        world = PlanningWorld(config(camera=UAVCamera(160, 120), render=RenderSettings(spp=4)), seed=3)
        grid = target_grid(world.target, OccupancyConfig(grid_resolution=16))
        planner = tiny(depth="stereo", partners=("back", "forward", "up"), agree=agree)
        planner.measure(world, grid, world.start)
        known[agree] = (grid.state != UNKNOWN).sum()
    assert 0 < known[2] < known[0]
    voting = tiny(LOOKAHEAD_FLIGHT, "stereo", votes=True)
    assert len(voting.plan(PlanningWorld(config(), seed=3), 3)) == 3
    assert target_grid(world.target, OccupancyConfig(grid_resolution=16, votes=True)).votes


def test_stereo_measures_the_building_and_blank_frames_measure_nothing():
    world = PlanningWorld(config(camera=UAVCamera(160, 120), render=RenderSettings(spp=4)), seed=3)
    known = {}
    for blank in (False, True):
        planner = LookaheadPlanner(grid=16, rays=8, depth="stereo", blank_images=blank)
        grid = target_grid(world.target, OccupancyConfig(grid_resolution=16))
        planner.measure(world, grid, world.start)
        known[blank] = (grid.state != UNKNOWN).mean()
    assert known[True] == 0.0 and known[False] > 0.05  # blank frames match nothing: the grid stays unknown
    small = PlanningWorld(config(), seed=3)
    views = LookaheadPlanner(grid=16, rays=8, depth="stereo").plan(small, 3)
    assert views[0] == small.start and len(views) == 3
    stereo = make_planner("lookahead-stereo", PlanSettings())
    assert (stereo.name, stereo.flight, stereo.depth) == ("lookahead-stereo", STEREO_FLIGHT, "stereo")
    assert stereo.options == LookaheadOptions(forward=True, sides=STEREO_SIDES, allowance_m=STEREO_HINGE[0],
                                              excess=STEREO_HINGE[1], battery_per_view_m=STEREO_PER_VIEW,
                                              steep_deg=STEREO_STEEP, steep_measures=False, route=True,
                                              votes=True)
    assert STEREO_HINGE == (13.0, 2.0) and STEREO_SIDES == 1.0  # round 31's setting
    assert STEREO_PER_VIEW == 1.0  # round 33's: 13 m up to 13 views, one a view past them
    assert STEREO_STEEP == 60.0  # round 36's blind band, confirmed in round 37
    assert STEREO_ROUTE  # round 39: the rest of the flight planned as a whole
    assert STEREO_VOTES  # round 51: one vote an image clears stereo's floaters
    assert make_planner("lookahead-stereo:0.2", PlanSettings(blank_images=True)).blank_images
    with pytest.raises(ValueError, match="depth from"):
        LookaheadPlanner(depth="lidar")


def test_a_ceiling_holds_every_step_at_or_under_it_and_changes_a_climbing_flight():
    world = PlanningWorld(config(), seed=3)
    free = tiny(0.0, forward=True, sides=50.0).plan(world, 6)
    assert max(v.elevation for v in free[1:]) > np.radians(30)  # the free flight climbs past it
    held = tiny(0.0, forward=True, sides=50.0, ceiling_deg=30.0).plan(world, 6)
    assert held != free and max(v.elevation for v in held[1:]) <= np.radians(30) + 1e-12
    with pytest.raises(ValueError, match="at most 90 .0: none., its sectors 4 or 8, its bands 1 to 3, got "
                                         "0.0, 0.0, 91, 4, 3"):
        LookaheadOptions(ceiling_deg=91)


def test_the_planner_builds_its_grid_with_the_padding_free_when_asked(monkeypatch):
    asked, build = [], lookahead_module.target_grid
    monkeypatch.setattr(lookahead_module, "target_grid", lambda *args: asked.append(args[-1]) or build(*args))
    world = PlanningWorld(config(), seed=3)
    tiny(0.0, forward=True).plan(world, 2)
    tiny(0.0, forward=True, padding_free=True).plan(world, 2)
    assert asked == [False, True]


def test_in_box_fuses_only_the_stereo_depths_inside_the_targets_bounds_grown_by_a_voxel():
    world = PlanningWorld(config(camera=UAVCamera(160, 120), render=RenderSettings(spp=4)), seed=3)
    grid = target_grid(world.target, OccupancyConfig(grid_resolution=16))
    lower, upper = world.target.bounds()
    for in_box in (False, True):
        points = []
        for depth, at in tiny(depth="stereo", in_box=in_box).measured(world, grid, world.start):
            c2w, kept = viewpoint_to_c2w(at, world.target.center()), np.isfinite(depth)
            rays = pixel_rays(world.camera.K, world.camera.width, world.camera.height)[kept]
            points.append((rays * depth[kept][:, None]) @ c2w[:3, :3].T + c2w[:3, 3])
        points = np.concatenate(points)
        margin = grid.voxel_size + 1e-5
        outside = np.any((points < lower - margin) | (points > upper + margin), axis=-1)
        assert len(points) > 1000 and outside.any() != in_box  # stereo alone lands some outside; in_box none
