"""The trait family `family:SEED`: buildings where no single orbit is best (issue 26).

Each seed has one trait (`scenes.family_splits`, which also splits the seeds and holds one trait out):

- `tower`: a free-standing round tower of 5 to 8 storeys (tall and slender: a low ring sees no roof);
- `courtyard`: four wings round a court entered through a gap (the court's walls face inwards);
- `u_plan`, `l_plan`: deep wings that hide the inner facades from most azimuths;
- `arcade`: deep overhangs, a colonnade under pagoda eaves or jettied storeys with balconies all round
  (soffits and recessed walls seen only from low);
- `hall`: a low wide one-storey hall (mostly roof: seen from high);
- `compound` (held out): a house, a tower and a barn inside a perimeter wall with a gate (the wall hides
  the ground storeys from low rings, the parts hide each other).

Buildings are built from `BuildingSpec`s with the same grammar, textures and light as `random:SEED`
(`scenes.buildings`), normalised like every scene; textures reuse 16 seeds (SEED % 16).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import manifold3d as mf
import numpy as np

from scenes.buildings import BuildingSpec, assemble, textured_scene
from scenes.csg import SolidBuilder
from scenes.family_splits import family_trait
from scenes.model import Scene
from scenes.presets import _PAINT, _ROOFS, _WALLS, _finishes, random_lighting
from scenes.solids import box
from scenes.surface import Finish


@dataclass(frozen=True)
class FamilyBuilding:
    """One `family:SEED` building: its trait, its parts (each placed in metres) and a perimeter wall."""

    trait: str
    """The seed's trait (`scenes.family_splits.TRAITS`)."""
    parts: tuple[tuple[BuildingSpec, tuple[float, float]], ...]
    """Each part's spec and the (x, y) offset of its plan's centre, metres."""
    wall: tuple[float, float, float, float, float] | None = None
    """A perimeter wall (x0, y0, x1, y1, height), metres, with a gate in its front; None for none."""


class _Shifted(SolidBuilder):
    """A view of a builder that moves every solid by an (x, y) offset before adding or cutting it."""

    def __init__(self, target: SolidBuilder, offset: tuple[float, float]) -> None:
        self._target, self._offset = target, (float(offset[0]), float(offset[1]), 0.0)

    def add(self, solid: mf.Manifold, material: str) -> None:
        """Union `solid`, moved, into the target."""
        self._target.add(solid.translate(self._offset), material)

    def cut(self, solid: mf.Manifold, material: str) -> None:
        """Subtract `solid`, moved, from the target."""
        self._target.cut(solid.translate(self._offset), material)


def _base(rng: np.random.Generator) -> BuildingSpec:
    """The look every part of one building shares: windows, finishes, light, ground."""
    pick = lambda options: options[int(rng.integers(len(options)))]  # noqa: E731
    walls = [pick(_WALLS) for _ in range(4)]
    return BuildingSpec(
        bay_w=float(rng.uniform(2.0, 2.8)),
        window=(float(rng.uniform(0.8, 1.1)), float(rng.uniform(1.1, 1.7))),
        shutters=bool(rng.random() < 0.5),
        wall_roles=("walls_0", "walls_1"),
        storey_h=float(rng.uniform(2.7, 3.3)),
        plinth_h=float(rng.uniform(0.3, 0.7)),
        steps=int(rng.integers(0, 4)),
        finishes=_finishes(
            **{f"walls_{k}": Finish(wall) for k, wall in enumerate(walls)},
            gable=Finish(walls[1]),
            roof=Finish(pick(_ROOFS)),
            shutters=Finish(pick(_PAINT)),
            trim=Finish(pick(_WALLS)),
            compound_wall=Finish(pick(("stone_rubble", "stone_ashlar", "brick_red"))),
        ),
        lighting=random_lighting(rng),
        ground=Finish(pick(("grass", "gravel", "forest_floor"))),
    )


def _storeys(rng: np.random.Generator, low: int, high: int) -> int:
    return int(rng.integers(low, high + 1))


def _tower(base: BuildingSpec, rng: np.random.Generator) -> BuildingSpec:
    return replace(base, footprint="tower", storeys=_storeys(rng, 5, 8), chimneys=0,
                   tower_radius=float(rng.uniform(1.8, 2.6)), wall_roles=("walls_2",))


def _courtyard(base: BuildingSpec, rng: np.random.Generator) -> BuildingSpec:
    return replace(base, footprint="courtyard", width=float(rng.uniform(16.0, 22.0)),
                   depth=float(rng.uniform(5.5, 7.0)), wing=float(rng.uniform(6.0, 10.0)),
                   storeys=_storeys(rng, 1, 2), roof="hip" if rng.random() < 0.6 else "flat",
                   pitch_deg=float(rng.uniform(30.0, 45.0)), overhang=float(rng.uniform(0.4, 0.8)),
                   chimneys=int(rng.integers(0, 3)))


def _wings(base: BuildingSpec, rng: np.random.Generator, footprint: str) -> BuildingSpec:
    roofs = ("gable", "hip", "flat") if footprint == "U" else ("gable", "hip")
    return replace(base, footprint=footprint, width=float(rng.uniform(14.0, 20.0)),
                   depth=float(rng.uniform(6.0, 8.0)), wing=float(rng.uniform(7.0, 13.0)),
                   storeys=_storeys(rng, 1, 3), roof=roofs[int(rng.integers(len(roofs)))],
                   pitch_deg=float(rng.uniform(30.0, 50.0)), overhang=float(rng.uniform(0.4, 1.0)),
                   chimneys=int(rng.integers(0, 3)), porch=bool(rng.random() < 0.4))


def _arcade(base: BuildingSpec, rng: np.random.Generator) -> BuildingSpec:
    storeys = _storeys(rng, 2, 3)
    shape = dict(width=float(rng.uniform(10.0, 14.0)), depth=float(rng.uniform(7.5, 10.0)), storeys=storeys)
    if rng.random() < 0.5:  # a colonnade under deep pagoda eaves
        return replace(base, **shape, roof="pagoda", jetty=-1.2, pitch_deg=float(rng.uniform(30.0, 36.0)),
                       overhang=float(rng.uniform(1.8, 2.4)), colonnade=True, chimneys=0,
                       platform=int(rng.integers(0, 3)), steps=0)
    return replace(base, **shape, roof="gable", jetty=float(rng.uniform(0.5, 0.8)),
                   pitch_deg=float(rng.uniform(22.0, 30.0)), overhang=float(rng.uniform(1.5, 2.2)),
                   balcony_storeys=tuple(range(1, storeys)), balcony_all_round=True,
                   balcony_depth=float(rng.uniform(1.2, 1.6)), chimneys=1)


def _hall(base: BuildingSpec, rng: np.random.Generator) -> BuildingSpec:
    return replace(base, width=float(rng.uniform(20.0, 28.0)), depth=float(rng.uniform(12.0, 18.0)),
                   storeys=1, storey_h=float(rng.uniform(3.6, 4.8)), roof="gable" if rng.random() < 0.6
                   else "hip", pitch_deg=float(rng.uniform(12.0, 22.0)),
                   overhang=float(rng.uniform(0.6, 1.0)), bay_w=float(rng.uniform(2.8, 3.4)),
                   chimneys=0, porch=bool(rng.random() < 0.5))


def _compound(base: BuildingSpec, rng: np.random.Generator) -> FamilyBuilding:
    """A house, a tower at its left and a barn at its right, set back, inside a wall with a gate."""
    house = replace(base, width=float(rng.uniform(10.0, 13.0)), depth=float(rng.uniform(7.0, 9.0)),
                    storeys=2, roof="gable", pitch_deg=float(rng.uniform(35.0, 50.0)), overhang=0.6,
                    chimneys=1)
    tower = replace(_tower(base, rng), storeys=_storeys(rng, 3, 5), tower_radius=float(rng.uniform(1.8, 2.2)))
    barn = replace(base, width=float(rng.uniform(7.0, 9.0)), depth=float(rng.uniform(5.0, 6.0)), storeys=1,
                   roof="gable", ridge_along_x=False, pitch_deg=float(rng.uniform(40.0, 50.0)),
                   overhang=0.5, chimneys=0, steps=0, wall_roles=("walls_3",))
    gap = float(rng.uniform(2.0, 3.5))
    tower_x = -(house.width / 2 + gap + tower.tower_radius + 1.0)
    barn_x, barn_y = house.width / 2 + gap + barn.width / 2 + 1.0, float(rng.uniform(1.0, 3.0))
    parts = ((house, (0.0, 0.0)), (tower, (tower_x, -1.0)), (barn, (barn_x, barn_y)))
    margin = float(rng.uniform(2.5, 4.0))
    lo = (tower_x - tower.tower_radius - margin, -house.depth / 2 - margin - 1.5)
    hi = (barn_x + barn.width / 2 + margin, max(house.depth / 2, barn_y + barn.depth / 2) + margin)
    return FamilyBuilding("compound", parts, (*lo, *hi, float(rng.uniform(2.2, 3.0))))


def family_building(seed: int) -> FamilyBuilding:
    """The trait, parts and wall of `family:SEED`, drawn by `seed`."""
    trait = family_trait(seed)
    rng = np.random.default_rng([seed, 0xFA3117])
    base = _base(rng)
    if trait == "compound":
        return _compound(base, rng)
    makers = {"tower": _tower, "courtyard": _courtyard, "arcade": _arcade, "hall": _hall,
              "u_plan": lambda b, r: _wings(b, r, "U"), "l_plan": lambda b, r: _wings(b, r, "L")}
    return FamilyBuilding(trait, ((makers[trait](base, rng), (0.0, 0.0)),))


def _perimeter(builder: SolidBuilder, wall: tuple[float, float, float, float, float]) -> None:
    """A wall of 0.5 m round (x0, y0, x1, y1), `height` tall, with a 3.5 m gate in the middle of its front."""
    x0, y0, x1, y1, height = wall
    t, gate = 0.5, 1.75
    for lo, hi in (((x0, y0), (-gate, y0 + t)), ((gate, y0), (x1, y0 + t)), ((x0, y1 - t), (x1, y1)),
                   ((x0, y0), (x0 + t, y1)), ((x1 - t, y0), (x1, y1))):
        builder.add(box((lo[0], lo[1], 0.0), (hi[0], hi[1], height)), "compound_wall")


def build_family(seed: int, detail: bool = True) -> Scene:
    """The normalised, textured building `family:SEED` (`detail`: unique surface detail, else the tiled
    textures alone)."""
    building = family_building(seed)
    builder = SolidBuilder()
    for k, (spec, offset) in enumerate(building.parts):
        assemble(spec, seed % 16 + 16 * k, _Shifted(builder, offset))
    if building.wall is not None:
        _perimeter(builder, building.wall)
    look = building.parts[0][0]
    return textured_scene(f"family:{seed}", builder.triangles(), look, seed % 16, detail)
