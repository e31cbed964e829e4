"""The occupancy grid: hand-worked carving and gain, the z-depth convention, and a rendered depth image."""

from __future__ import annotations

import numpy as np
import open3d as o3d
import pytest
import trimesh

from nbv.recon.occupancy import FREE, OCCUPIED, SIGHT_BINS, UNKNOWN, OccupancyGrid, sight_bin
from render.camera import UAVCamera
from render.raycast import DepthRaycaster
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene

ONE_PIXEL = np.eye(3)  # f = 1, principal point at pixel (0, 0): the single ray is the optical axis
ALONG_X = np.array([[0, 0, 1, -1.0], [1, 0, 0, 0.5], [0, 1, 0, 0.5], [0, 0, 0, 1]])  # at x = -1, looks +x
AGAINST_X = np.array([[0, 0, -1, 5.0], [-1, 0, 0, 0.5], [0, 1, 0, 0.5], [0, 0, 0, 1]])  # at x = 5, looks -x


def row_of_four() -> OccupancyGrid:
    """Four 1 m voxels along x: [0, 4] x [0, 1] x [0, 1]."""
    grid = OccupancyGrid(np.zeros(3), np.array([4.0, 1.0, 1.0]), resolution=4)
    assert grid.state.shape == (4, 1, 1) and grid.voxel_size == 1.0
    return grid


def test_one_ray_frees_the_voxels_before_its_hit_and_occupies_the_hit():
    grid = row_of_four()
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, ALONG_X)  # hits x = 2.5, in voxel 2
    assert grid.state[:, 0, 0].tolist() == [FREE, FREE, OCCUPIED, UNKNOWN]  # behind the hit: unknown


def test_no_hit_frees_the_whole_ray_and_a_later_ray_does_not_clear_a_hit():
    grid = row_of_four()
    grid.integrate(np.array([[0.0]], np.float32), ONE_PIXEL, ALONG_X)  # depth 0: nothing in range
    assert grid.state[:, 0, 0].tolist() == [FREE] * 4
    grid = row_of_four()
    grid.integrate(np.array([[2.5]], np.float32), ONE_PIXEL, ALONG_X)  # voxel 1 occupied
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, ALONG_X)  # a later ray through it
    assert grid.state[:, 0, 0].tolist() == [FREE, OCCUPIED, OCCUPIED, UNKNOWN]


def test_with_votes_later_rays_through_a_floater_clear_it_and_a_surface_seen_twice_holds():
    grid = OccupancyGrid(np.zeros(3), np.array([4.0, 1.0, 1.0]), resolution=4, votes=True)
    grid.integrate(np.array([[2.5]], np.float32), ONE_PIXEL, ALONG_X)  # a false match: voxel 1, one hit
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, ALONG_X)  # through it to voxel 2: one pass
    assert grid.state[:, 0, 0].tolist() == [FREE, OCCUPIED, OCCUPIED, UNKNOWN]  # a tie: still occupied
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, ALONG_X)  # a second pass outvotes the hit
    assert grid.state[:, 0, 0].tolist() == [FREE, FREE, OCCUPIED, UNKNOWN]
    assert grid.hits[:4].tolist() == [0, 1, 2, 0] and grid.passes[:4].tolist() == [3, 2, 0, 0]
    grid.integrate(np.array([[2.5]], np.float32), ONE_PIXEL, AGAINST_X)  # from the other side: voxel 2 hit
    assert grid.state[:, 0, 0].tolist() == [FREE, FREE, OCCUPIED, FREE]
    assert grid.hits[2] == 3 and grid.passes[3] == 1


def test_a_pixel_not_measured_carves_and_marks_nothing():
    grid = row_of_four()
    grid.integrate(np.array([[np.nan]], np.float32), ONE_PIXEL, ALONG_X)  # stereo found no match
    assert grid.state[:, 0, 0].tolist() == [UNKNOWN] * 4
    grid.integrate(np.array([[2.5, np.nan]], np.float32), ONE_PIXEL, ALONG_X)  # the first pixel is the axis
    assert grid.state[:, 0, 0].tolist() == [FREE, OCCUPIED, UNKNOWN, UNKNOWN]


def test_gain_counts_the_unknown_voxels_a_view_reaches_before_an_occupied_one():
    grid = row_of_four()
    assert grid.gain(ONE_PIXEL, ALONG_X, 1, 1) == 4  # all unknown: nothing stops the ray
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, ALONG_X)
    assert grid.gain(ONE_PIXEL, ALONG_X, 1, 1) == 0  # the known side: free, then the occupied voxel
    assert grid.gain(ONE_PIXEL, AGAINST_X, 1, 1) == 1  # the far side: voxel 3, then voxel 2 stops it
    grid.state[3] = OCCUPIED
    assert grid.gain(ONE_PIXEL, AGAINST_X, 1, 1) == 0


def test_reached_names_the_voxels_gain_counts():
    grid = row_of_four()
    assert grid.reached(ONE_PIXEL, ALONG_X, 1, 1).tolist() == [True] * 4
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, ALONG_X)
    assert grid.reached(ONE_PIXEL, AGAINST_X, 1, 1).tolist() == [False, False, False, True]  # voxel 3 only


def test_first_counts_only_each_rays_first_unknown_voxels():
    grid = row_of_four()
    assert grid.reached(ONE_PIXEL, ALONG_X, 1, 1, first=1).tolist() == [True, False, False, False]
    assert grid.gain(ONE_PIXEL, AGAINST_X, 1, 1, first=2) == 2  # voxels 3 and 2, from the far side
    grid.integrate(np.array([[0.0]], np.float32), ONE_PIXEL, ALONG_X)  # no hit: the row is free
    grid.state[2] = UNKNOWN
    assert grid.reached(ONE_PIXEL, ALONG_X, 1, 1, first=1).tolist() == [False, False, True, False]
    assert grid.gain(ONE_PIXEL, ALONG_X, 1, 1, first=0) == 1  # free voxels let the ray on and count nothing
    with pytest.raises(ValueError, match="first unknown voxels to count must be >= 0"):
        grid.reached(ONE_PIXEL, ALONG_X, 1, 1, first=-1)


def test_sight_bins_split_quadrants_and_looking_up_level_or_down_at_10_degrees():
    up, down = np.sin(np.radians(10.5)), np.sin(np.radians(9.5))
    bins = sight_bin(np.array([[0, -1.0, 0], [1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0],
                               [np.sqrt(1 - up ** 2), 0, up], [np.sqrt(1 - down ** 2), 0, down],
                               [np.sqrt(1 - up ** 2), 0, -up]]))
    assert bins.tolist() == [1, 4, 7, 10, 5, 4, 3]  # -y, +x, -x, +y quadrants level; then +x up, level, down
    assert SIGHT_BINS == 12


def test_a_steep_band_gives_rays_looking_down_past_it_bins_of_their_own():
    def looking_down(degrees: float) -> np.ndarray:
        return np.array([np.cos(np.radians(degrees)), 0, -np.sin(np.radians(degrees))])

    rays = np.array([looking_down(d) for d in (61, 59, 11, 0, -11)])  # the +x quadrant
    assert sight_bin(rays).tolist() == [3, 3, 3, 4, 5]  # down, down, down, level, up
    assert sight_bin(rays, steep_deg=60).tolist() == [4, 5, 5, 6, 7]  # steep, down, down, level, up
    facing_minus_y = -rays[:, [1, 0, 2]] * [1, 1, -1]  # the same tilts in the -y quadrant (0)
    assert sight_bin(facing_minus_y, steep_deg=60).tolist() == [0, 1, 1, 2, 3]
    with pytest.raises(ValueError, match="steep band starts past the level band's 10 degrees and under 90"):
        OccupancyGrid(np.zeros(3), np.ones(3), resolution=2, steep_deg=10)


def test_eight_sectors_split_the_horizon_at_22_5_degrees_either_side_of_each_compass_point():
    def level(degrees: float) -> list[float]:
        return [np.cos(np.radians(degrees)), np.sin(np.radians(degrees)), 0.0]

    rays = np.array([level(d) for d in (0, 22, 23, 45, 90, 180, -44, -68)])
    assert (sight_bin(rays, sectors=8) // 3).tolist() == [0, 0, 1, 1, 2, 4, 7, 6]  # counter-clockwise from +x
    assert (sight_bin(rays) // 3).tolist() == [1, 1, 1, 1, 3, 2, 1, 0]  # the quadrants, for comparison
    steep = np.array([[np.cos(np.radians(61)), 0, -np.sin(np.radians(61))]])  # +x, 61 degrees down
    assert sight_bin(steep, 60, 8).tolist() == [0]  # sector 0, the steep band
    grid = OccupancyGrid(np.zeros(3), np.ones(3), resolution=2, steep_deg=60, sectors=8)
    assert grid.sight_bins == 32 and grid.side_bins().tolist() == [b for b in range(32) if b % 4]
    with pytest.raises(ValueError, match="sight bins split the horizon in 4 or 8, got 6"):
        OccupancyGrid(np.zeros(3), np.ones(3), resolution=2, sectors=6)
    with pytest.raises(ValueError, match="split the horizon into 4 or 8 sectors, got 3"):
        sight_bin(rays, sectors=3)


def test_eight_sectors_record_a_hit_past_the_first_16_bits():
    forward = np.array([np.sqrt(0.5), -np.sqrt(0.5), 0.0])  # level, 45 degrees clockwise of +x: sector 7
    down = np.array([0, 0, -1.0])
    c2w = np.eye(4)
    c2w[:3, :3] = np.column_stack([np.cross(down, forward), down, forward])  # OpenCV: x right, y down
    c2w[:3, 3] = np.full(3, 0.5) - 2 * forward  # 2 m short of the one voxel's centre
    grid = OccupancyGrid(np.zeros(3), np.ones(3), resolution=1, steep_deg=60, sectors=8)
    grid.integrate(np.array([[2.0]], np.float32), ONE_PIXEL, c2w)
    assert grid.sides.tolist() == [1 << (7 * 4 + 2)]  # sector 7, level (bin 30 of 32)
    assert np.argwhere(grid.sighted(ONE_PIXEL, c2w, 1, 1)).tolist() == [[0, 30]]


def test_a_grid_with_a_steep_band_records_a_hit_from_overhead_in_it():
    down = np.array([[1, 0, 0, 0.5], [0, -1, 0, 0.5], [0, 0, -1, 5.0], [0, 0, 0, 1]])  # at z = 5, looks -z
    column = [OccupancyGrid(np.zeros(3), np.array([1.0, 1.0, 4.0]), resolution=4, steep_deg=steep)
              for steep in (0.0, 60.0)]
    for grid in column:
        grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, down)  # voxel 1 (z 1 to 2) hit from above
    assert [grid.sides[:4].tolist() for grid in column] == [[0, 1 << 3, 0, 0], [0, 1 << 4, 0, 0]]
    assert [grid.sighted(ONE_PIXEL, down, 1, 1).shape for grid in column] == [(4, 12), (4, 16)]


def test_sides_record_the_direction_a_hit_was_measured_from_and_sighted_names_new_ones():
    grid = row_of_four()
    assert not grid.sighted(ONE_PIXEL, ALONG_X, 1, 1).any()  # nothing occupied: nothing met
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, ALONG_X)  # voxel 2 hit looking +x, level
    assert grid.sides[:4].tolist() == [0, 0, 1 << 4, 0]
    along, against = (grid.sighted(ONE_PIXEL, pose, 1, 1) for pose in (ALONG_X, AGAINST_X))
    assert along.shape == (4, SIGHT_BINS) and np.argwhere(along).tolist() == [[2, 4]]  # its own side again
    assert np.argwhere(against).tolist() == [[2, 7]]  # past unknown voxel 3, voxel 2 from -x: a new side
    grid.integrate(np.array([[0.0]], np.float32), ONE_PIXEL, AGAINST_X)  # no hit marks no side
    assert grid.sides[:4].tolist() == [0, 0, 1 << 4, 0]


def test_the_frontier_is_the_unknown_beside_free_space():
    grid = row_of_four()
    assert not grid.frontier().any()  # nothing known: no frontier
    grid.integrate(np.array([[1.5]], np.float32), ONE_PIXEL, ALONG_X)  # free, occupied, unknown, unknown
    assert not grid.frontier().any()  # the unknown lies behind the hit, not beside free space
    grid.state[:, 0, 0] = [UNKNOWN, FREE, UNKNOWN, OCCUPIED]
    assert grid.frontier().tolist() == [True, False, True, False]
    cube = OccupancyGrid(np.zeros(3), np.full(3, 3.0), resolution=3)
    cube.state[1, 1, 1] = FREE
    assert cube.frontier().sum() == 6  # its six face neighbours, not the edges or corners
    assert cube.frontier().reshape(3, 3, 3)[0, 1, 1] and not cube.frontier().reshape(3, 3, 3)[0, 0, 1]


def test_a_ray_that_misses_the_grid_gains_nothing_and_changes_nothing():
    grid = row_of_four()
    away = AGAINST_X.copy()
    away[0, 3] = -1.0  # at x = -1 looking along -x, away from the grid
    grid.integrate(np.array([[3.5]], np.float32), ONE_PIXEL, away)
    assert grid.gain(ONE_PIXEL, away, 1, 1) == 0 and np.all(grid.state == UNKNOWN)


def test_depth_is_z_depth_not_ray_length():
    # A wall across a 90-degree view: off-axis rays are longer than their z-depth by up to sqrt(2);
    # read as ray lengths, the corner pixels would place the wall 30 % too close.
    camera = UAVCamera(33, 33, focal_mm=18.0)  # fov_x = 90 degrees
    wall = trimesh.creation.box((0.02, 4.0, 4.0))
    wall.apply_translation((1.5, 0.0, 0.5))  # front face at x = 1.49
    c2w = ALONG_X.copy()
    c2w[:3, 3] = (0.0, 0.0, 0.5)
    depth = DepthRaycaster([wall], camera.K, camera.width, camera.height).depth(c2w)
    assert depth.min() == pytest.approx(1.49, abs=1e-4) and depth.max() == pytest.approx(1.49, abs=1e-4)
    grid = OccupancyGrid(np.array([0.0, -1.6, -1.1]), np.array([3.2, 1.6, 2.1]), resolution=32)  # 0.1 m
    grid.integrate(depth, camera.K, c2w)
    occupied_x = np.unique(np.nonzero(grid.state == OCCUPIED)[0])
    assert occupied_x.tolist() == [14]  # x in [1.4, 1.5): every pixel, corners too
    assert np.all(grid.state[:14, 16, 16] == FREE)  # along the optical axis, in front of the wall


def test_bad_grids_are_refused():
    with pytest.raises(ValueError, match="positive extent"):
        OccupancyGrid(np.zeros(3), np.array([1.0, 0.0, 1.0]), 8)
    with pytest.raises(ValueError, match="resolution"):
        OccupancyGrid(np.zeros(3), np.ones(3), 0)


def test_a_rendered_depth_image_occupies_voxels_on_the_true_surface():
    scene = load_scene("test_building")
    camera = UAVCamera(64, 48)
    renderer = MitsubaRenderer(scene, camera, RenderSettings(spp=1))
    c2w = viewpoint_to_c2w(Viewpoint(2.0, 0.6, 0.5), renderer.center)
    lower, upper = scene.bounds()
    grid = OccupancyGrid(lower - [0.05, 0.05, 0.0], upper + 0.05, resolution=32)
    grid.integrate(renderer.render_depth(c2w), camera.K, c2w)
    occupied = np.stack(np.nonzero(grid.state == OCCUPIED), -1)
    free = np.stack(np.nonzero(grid.state == FREE), -1)
    assert len(occupied) > 50 and len(free) > 2 * len(occupied)
    surface = o3d.t.geometry.RaycastingScene()
    for part in scene.parts:  # the ground too: it is in view
        surface.add_triangles(np.asarray(part.vertices, np.float32), np.asarray(part.faces, np.uint32))

    def distance(ijk: np.ndarray) -> np.ndarray:
        centres = grid.lower + (ijk + 0.5) * grid.voxel_size
        return surface.compute_distance(centres.astype(np.float32)).numpy()

    half_diagonal = np.sqrt(3) / 2 * grid.voxel_size
    assert distance(occupied).max() <= half_diagonal + 1e-4  # every occupied voxel holds surface
    near = grid.voxel_size / 2
    assert np.mean(distance(occupied) < near) > 0.8 > 0.1 > np.mean(distance(free) < near)  # free: off it
