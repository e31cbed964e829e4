"""The trait family `family:SEED`: every trait builds a closed, normalised building; splits and the
held-out trait are honoured; bad names are refused; `random:SEED` is unchanged by it.

Geometry only (textures are the shared code's, tested with the presets): a textured family building takes
tens of seconds to build in a fresh cache."""

from __future__ import annotations

import hashlib
from dataclasses import replace

import numpy as np
import pytest
import trimesh

from scenes import load_scene
from scenes.buildings import textured_scene
from scenes.csg import SolidBuilder
from scenes.family import _perimeter, _Shifted, assemble, family_building
from scenes.family_splits import (
    HELD_OUT_TRAIT,
    SEEN_TRAITS,
    TRAITS,
    family_seeds,
    family_split,
    family_trait,
    held_out,
    parse_family,
)
from scenes.presets import random_spec
from scenes.surface import Finish

ONE_PER_TRAIT = {"tower": 1, "courtyard": 2, "u_plan": 3, "l_plan": 6, "arcade": 7, "hall": 8, "compound": 0}
"""A seed of each trait, worked by hand from the rule in `scenes.family_splits`."""
RANDOM_3 = "f11fc31eccbb2757"
"""sha256 (first 16 hex digits) of random:3's solids (material name and triangle corners, by material),
computed on main (cd8b00a) before the family was added."""


def _solids(seed: int) -> dict[str, np.ndarray]:
    """`family:SEED`'s triangles by role, in metres (the geometry of `build_family`, before textures)."""
    building, builder = family_building(seed), SolidBuilder()
    for k, (spec, offset) in enumerate(building.parts):
        assemble(spec, seed % 16 + 16 * k, _Shifted(builder, offset))
    if building.wall is not None:
        _perimeter(builder, building.wall)
    return builder.triangles()


def _triangles(seed: int) -> np.ndarray:
    """(F, 3, 3) corners of `family:SEED`'s solids, metres."""
    return np.concatenate(list(_solids(seed).values()))


@pytest.mark.parametrize("trait, seed", ONE_PER_TRAIT.items())
def test_each_trait_is_closed_above_the_ground_and_normalised(trait, seed):
    assert family_trait(seed) == trait == family_building(seed).trait
    solids = _solids(seed)
    look = family_building(seed).parts[0][0]
    plain = replace(look, finishes={role: Finish(None) for role in look.finishes}, ground=Finish(None))
    scene = textured_scene(f"family:{seed}", solids, plain, 0)  # plain colours: no texture to generate
    lo, hi = scene.bounds()
    assert lo[2] == pytest.approx(0.0, abs=1e-9) and np.max(hi - lo) == pytest.approx(1.0)
    assert (lo[:2] + hi[:2]) / 2 == pytest.approx([0.0, 0.0], abs=1e-9)
    corners = np.concatenate(list(solids.values()))
    mesh = trimesh.Trimesh(corners.reshape(-1, 3), np.arange(3 * len(corners)).reshape(-1, 3))
    mesh.merge_vertices()
    assert mesh.area > 50.0  # square metres: a whole building, not a fragment
    edges, count = np.unique(np.sort(mesh.edges, axis=1), axis=0, return_counts=True)
    open_edges = edges[count == 1]
    above = open_edges[mesh.vertices[open_edges][:, :, 2].max(axis=1) > 1e-6]
    assert len(above) < 0.005 * len(edges)  # only the dropped footprints open, onto the ground
    height = corners[..., 2].max()
    spread = np.ptp(corners[..., :2].reshape(-1, 2), axis=0).max()
    if trait == "tower":
        assert height > 2 * spread  # taller than twice its width
    if trait == "hall":
        assert height < 0.45 * spread  # low and wide


def test_family_building_is_reproducible_and_seeds_differ():
    assert family_building(1) == family_building(1)
    first, again = _solids(1), _solids(1)
    assert first.keys() == again.keys() and all(np.array_equal(first[k], again[k]) for k in first)
    assert family_trait(11) == family_trait(1) and family_building(11) != family_building(1)


def test_splits_and_the_held_out_trait():
    assert [family_split(s) for s in range(6)] == ["test", "train", "train", "train", "validation", "test"]
    train, validation = family_seeds("train", 60), family_seeds("validation", 20)
    test = family_seeds("test", 20)
    assert {family_trait(s) for s in train} == {family_trait(s) for s in validation} == set(SEEN_TRAITS)
    assert HELD_OUT_TRAIT not in {family_trait(s) for s in train + validation}
    assert {family_trait(s) for s in test} == set(TRAITS)
    assert not any(held_out(f"family:{s}") for s in train + validation)
    assert all(held_out(f"family:{s}") for s in test)
    assert family_seeds("test", 3, trait=HELD_OUT_TRAIT) == [0, 10, 20]
    assert family_seeds("train", 2, trait="tower") == [1, 11]
    with pytest.raises(ValueError, match="held-out trait 'compound' has no train seeds"):
        family_seeds("train", 1, trait=HELD_OUT_TRAIT)
    with pytest.raises(ValueError, match="unknown trait 'dome'"):
        family_seeds("test", 1, trait="dome")
    with pytest.raises(ValueError, match="split must be one of train, validation, test"):
        family_seeds("val", 1)


def test_held_out_covers_presets_random_and_family():
    assert held_out("alpine_chalet") and held_out("random:5") and held_out("family:0")
    assert not held_out("medieval_tavern") and not held_out("random:6") and not held_out("family:9")


@pytest.mark.parametrize("spec", ["family:x", "family:-1", "family:", "family:1.5", "family:²"])
def test_bad_family_names_are_refused(spec):
    with pytest.raises(ValueError, match=r"expected family:SEED with SEED a non-negative integer"):
        load_scene(spec)
    assert parse_family("family:12") == 12


def test_random_buildings_are_unchanged():
    solids = assemble(random_spec(3), 3).triangles()
    digest = hashlib.sha256()
    for role in sorted(solids):
        digest.update(role.encode() + np.ascontiguousarray(solids[role]).tobytes())
    assert digest.hexdigest()[:16] == RANDOM_3
