"""Solid modelling, UV mapping and normalisation against analytic answers."""

from __future__ import annotations

import numpy as np
import pytest

from scenes.csg import SolidBuilder
from scenes.model import Material, Part
from scenes.normalise import normalise_parts, up_to_z
from scenes.solids import box, outline, wall_frames
from scenes.surface import make_part, planar_uv


def _area(corners: np.ndarray) -> float:
    return float(
        np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1).sum()
        / 2
    )


def test_union_drops_buried_and_ground_faces():
    b = SolidBuilder()
    b.add(box((0, 0, 0), (2, 2, 1)), "wall")
    b.add(box((0.5, 0.5, 0.5), (1.5, 1.5, 2)), "chimney")  # its foot is buried in the wall block
    tris = b.triangles()
    # Wall: 4 sides of 2 x 1 plus the top 4 minus the chimney's 1 x 1 footprint; no base face.
    assert _area(tris["wall"]) == pytest.approx(8 + 3)
    # Chimney: only what stands above the wall: 4 sides of 1 x 1 plus its top.
    assert _area(tris["chimney"]) == pytest.approx(5)
    assert all(t[..., 2].min() >= 0 for t in tris.values())


def test_cut_faces_take_the_cutters_material():
    b = SolidBuilder()
    b.add(box((0, 0, 0), (2, 1, 2)), "wall")
    b.cut(box((0.5, -0.5, 0.5), (1.5, 0.2, 1.5)), "reveal")  # a 1 x 1 recess, 0.2 deep, in the y = 0 face
    tris = b.triangles()
    assert _area(tris["reveal"]) == pytest.approx(1 + 4 * 0.2)
    # Front 2 x 2 less the 1 x 1 opening, back 2 x 2, two 1 x 2 ends, the 2 x 1 top; no base.
    assert _area(tris["wall"]) == pytest.approx(3 + 4 + 4 + 2)


def test_outline_of_an_l_is_one_counter_clockwise_hexagon():
    (poly,) = outline([(0, 0, 10, 6), (0, 0, 5, 12)])
    assert len(poly) == 6
    x, y = poly[:, 0], poly[:, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) == pytest.approx(10 * 6 + 5 * 6)
    for f in wall_frames(poly, 0.0):  # outward normals point away from the centroid side
        mid = f.point(f.length / 2, 0.01, 0.0)
        inside = (0 < mid[0] < 10 and 0 < mid[1] < 6) or (0 < mid[0] < 5 and 0 < mid[1] < 12)
        assert not inside


def test_planar_uv_on_a_wall_runs_along_it_with_the_image_up():
    wall = np.array([[[0, 0, 0], [2, 0, 0], [2, 0, 1]]], float)  # faces -y, seen from outside
    uv = planar_uv(wall, tile_m=0.5)[0]
    assert uv[1, 0] - uv[0, 0] == pytest.approx(4.0)  # 2 m along the wall = 4 tiles
    assert uv[2, 1] - uv[1, 1] == pytest.approx(-2.0)  # 1 m up = 2 tiles up the image (v shrinks)
    roof = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 1]]], float)
    assert planar_uv(roof, 1.0)[0, 2, 1] == pytest.approx(-np.sqrt(2))  # along the slope


def test_make_part_merges_shared_corners():
    corners = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    part = make_part("quad", corners, planar_uv(corners, 1.0), Material("m"))
    assert part.vertices.shape == (4, 3) and part.faces.shape == (2, 3)


def test_up_axis_y_is_a_proper_rotation():
    pts = np.eye(3)
    rotated = up_to_z(pts, "y")
    assert np.allclose(rotated[1], [0, 0, 1])  # y up becomes z up
    assert np.linalg.det(rotated) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="up axis"):
        up_to_z(pts, "x")


def test_normalise_parts_centres_scales_and_grounds_the_target():
    target = Part(
        "t", np.array([[1, 2, 3], [5, 2, 3], [1, 4, 5]], float), np.array([[0, 1, 2]]), Material("m")
    )
    ground = Part(
        "g",
        np.array([[0, 0, 3], [1, 0, 3], [0, 1, 3]], float),
        np.array([[0, 1, 2]]),
        Material("g"),
        target=False,
    )
    t, g = normalise_parts([target, ground])
    assert t.vertices.min(0) == pytest.approx([-0.5, -0.25, 0.0])
    assert t.vertices.max(0) == pytest.approx([0.5, 0.25, 0.5])
    assert g.vertices[0] == pytest.approx([-0.75, -0.75, 0.0])  # same transform, no say in the bounds
