"""The four named buildings that stand in for the paper's targets, and the `random:SEED` family.

Paper Sec. V uses four photoreal buildings (Medieval Tavern, Forest Ruin
House, Alpine Chalet, Imperial Temple). Ours are generated: each preset is a
`BuildingSpec` with its own footprint, roof, materials and light.

`random:SEED` draws a building from the grammar for training variety. Seeds
are split deterministically: SEED % 5 == 0 is a test building, every other seed
a training building (`seed_split`), so a policy is evaluated on buildings it
never trained on. Random buildings reuse 16 texture seeds (SEED % 16) to bound
the texture cache.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from scenes.buildings import BuildingSpec, build_building
from scenes.model import Lighting, Scene
from scenes.surface import Finish

_COMMON = {
    "reveal": Finish("stone_ashlar"),
    "glass": Finish("glass", roughness=0.08),
    "trim": Finish("stone_ashlar"),
    "door": Finish("timber_planks"),
    "shutters": Finish("paint_green"),
    "beams": Finish("timber_dark"),
    "balcony": Finish("timber_planks", rotate=True),
    "plinth": Finish("stone_rubble"),
    "chimney": Finish("brick_red"),
    "steps": Finish("stone_ashlar"),
    "columns": Finish("lacquer_red"),
    "broken": Finish("stone_rubble"),
    "quoins": Finish("stone_sandstone"),
}


def _finishes(**roles: Finish) -> dict[str, Finish]:
    return {**_COMMON, **roles}


PRESETS: dict[str, BuildingSpec] = {
    "medieval_tavern": BuildingSpec(
        footprint="L",
        width=13.0,
        depth=7.5,
        wing=4.5,
        storeys=2,
        storey_h=3.0,
        jetty=0.35,
        roof="gable",
        pitch_deg=52.0,
        overhang=0.5,
        bay_w=2.3,
        window=(0.9, 1.3),
        shutters=True,
        wall_roles=("stone_walls", "plaster_walls"),
        quoin_storeys=(0,),
        timber_storeys=(1,),
        chimneys=2,
        steps=3,
        porch=True,
        finishes=_finishes(
            stone_walls=Finish("stone_rubble"),
            plaster_walls=Finish("plaster_white"),
            gable=Finish("timber_planks"),
            roof=Finish("roof_tiles_red"),
            shutters=Finish("paint_blue"),
            trim=Finish("timber_dark"),
        ),
        lighting=Lighting(
            sun_azimuth_deg=220.0, sun_elevation_deg=35.0, sun_irradiance=3.2, sky_radiance=(0.6, 0.58, 0.55)
        ),
        ground=Finish("gravel"),
    ),
    "forest_ruin_house": BuildingSpec(
        footprint="rectangle",
        width=10.0,
        depth=7.0,
        storeys=2,
        storey_h=2.8,
        roof="gable",
        pitch_deg=48.0,
        overhang=0.35,
        bay_w=2.0,
        window=(0.8, 1.2),
        wall_roles=("walls",),
        quoin_storeys=(0, 1),
        chimneys=1,
        steps=2,
        tower=True,
        tower_radius=2.0,
        ruined=True,
        finishes=_finishes(
            walls=Finish("stone_mossy"),
            gable=Finish("stone_mossy"),
            roof=Finish("roof_slate"),
            glass=Finish("timber_grey"),
            shutters=Finish("timber_grey"),
            trim=Finish("stone_rubble"),
            plinth=Finish("stone_mossy"),
            chimney=Finish("stone_rubble"),
            broken=Finish("stone_rubble"),
        ),
        lighting=Lighting(
            sun_azimuth_deg=120.0, sun_elevation_deg=60.0, sun_irradiance=1.6, sky_radiance=(0.7, 0.76, 0.72)
        ),
        ground=Finish("forest_floor"),
    ),
    "alpine_chalet": BuildingSpec(
        footprint="rectangle",
        width=10.0,
        depth=12.0,
        storeys=3,
        storey_h=2.7,
        plinth_h=0.4,
        roof="gable",
        pitch_deg=24.0,
        overhang=1.5,
        ridge_along_x=False,
        bay_w=1.8,
        window=(0.9, 1.2),
        shutters=True,
        wall_roles=("stone_walls", "timber_walls"),
        quoin_storeys=(0,),
        balcony_storeys=(1, 2),
        balcony_depth=1.3,
        balcony_all_round=True,
        chimneys=1,
        steps=2,
        finishes=_finishes(
            stone_walls=Finish("stone_ashlar"),
            timber_walls=Finish("timber_planks", rotate=True),
            gable=Finish("timber_planks", rotate=True),
            roof=Finish("roof_shingles"),
            trim=Finish("timber_dark"),
            shutters=Finish("paint_green"),
            chimney=Finish("stone_ashlar"),
            plinth=Finish("stone_ashlar"),
        ),
        lighting=Lighting(
            sun_azimuth_deg=300.0, sun_elevation_deg=55.0, sun_irradiance=3.6, sky_radiance=(0.5, 0.6, 0.75)
        ),
        ground=Finish("grass"),
    ),
    "imperial_temple": BuildingSpec(
        footprint="rectangle",
        width=11.0,
        depth=8.5,
        storeys=3,
        storey_h=3.6,
        plinth_h=0.3,
        jetty=-1.5,
        roof="pagoda",
        pitch_deg=34.0,
        overhang=1.9,
        bay_w=1.6,
        window=(0.9, 1.3),
        wall_roles=("walls",),
        chimneys=0,
        steps=0,
        platform=3,
        colonnade=True,
        finishes=_finishes(
            walls=Finish("lacquer_red"),
            gable=Finish("lacquer_red"),
            roof=Finish("roof_glazed", roughness=0.25),
            trim=Finish("stone_sandstone"),
            plinth=Finish("stone_sandstone"),
            steps=Finish("stone_sandstone"),
            reveal=Finish("lacquer_red"),
            beams=Finish("paint_green"),
            door=Finish("lacquer_red"),
        ),
        lighting=Lighting(
            sun_azimuth_deg=60.0, sun_elevation_deg=45.0, sun_irradiance=3.4, sky_radiance=(0.62, 0.6, 0.56)
        ),
        ground=Finish("gravel"),
    ),
}
"""The named presets, by scene name."""

TEST_EVERY = 5
"""`random:SEED` is a test building when SEED % TEST_EVERY == 0, else a training building."""


def seed_split(seed: int) -> str:
    """'test' or 'train': which split the building `random:SEED` belongs to."""
    return "test" if seed % TEST_EVERY == 0 else "train"


def split_seeds(split: str, count: int, start: int = 0) -> list[int]:
    """The first `count` seeds >= `start` of `split` ('train' or 'test')."""
    if split not in ("train", "test"):
        raise ValueError(f"split must be 'train' or 'test', got {split!r}")
    seeds, seed = [], start
    while len(seeds) < count:
        if seed_split(seed) == split:
            seeds.append(seed)
        seed += 1
    return seeds


def build_preset(name: str, seed: int = 0, detail: bool = True) -> Scene:
    """The preset building `name` (`detail`: unique surface detail, else the tiled textures alone)."""
    if name not in PRESETS:
        raise ValueError(f"unknown preset {name!r}; presets: {', '.join(PRESETS)}")
    return build_building(name, PRESETS[name], seed, detail)


_WALLS = (
    "stone_rubble",
    "stone_ashlar",
    "stone_sandstone",
    "brick_red",
    "brick_yellow",
    "plaster_white",
    "plaster_ochre",
    "timber_planks",
)
_ROOFS = ("roof_tiles_red", "roof_slate", "roof_shingles", "roof_glazed")
_PAINT = ("paint_green", "paint_blue", "lacquer_red", "timber_dark")


def random_lighting(rng: np.random.Generator) -> Lighting:
    """A sun and sky drawn for a procedural building (the `random:SEED` and `family:SEED` families)."""
    return Lighting(
        sun_azimuth_deg=float(rng.uniform(0, 360)),
        sun_elevation_deg=float(rng.uniform(25, 70)),
        sun_irradiance=float(rng.uniform(2.0, 3.8)),
        sky_radiance=tuple(float(c) for c in rng.uniform(0.45, 0.75, 3)),
    )


def random_spec(seed: int) -> BuildingSpec:
    """A building drawn from the grammar by `seed` (footprint, storeys, roof, details, finishes, light)."""
    rng = np.random.default_rng([seed, 0x5CE7E])
    pick = lambda options: options[int(rng.integers(len(options)))]  # noqa: E731
    footprint = pick(("rectangle", "rectangle", "L", "U", "cross", "tower"))
    roof = (
        pick(("gable", "gable", "hip", "flat", "pagoda"))
        if footprint == "rectangle"
        else pick(("gable", "hip", "flat"))
    )
    storeys = int(rng.integers(2, 4)) if roof == "pagoda" else int(rng.integers(1, 4))
    walls = [pick(_WALLS) for _ in range(2)]
    width = float(rng.uniform(9.0, 14.0))
    depth = float(rng.uniform(6.5, 0.85 * width))
    spec = BuildingSpec(
        footprint=footprint,
        width=width,
        depth=depth,
        wing=float(rng.uniform(3.0, 6.0)),
        storeys=storeys,
        storey_h=float(rng.uniform(2.7, 3.3)),
        plinth_h=float(rng.uniform(0.3, 0.8)),
        jetty=-1.2 if roof == "pagoda" else float(pick((0.0, 0.0, 0.3))),
        roof=roof,
        pitch_deg=float(rng.uniform(25.0, 55.0)) if roof != "pagoda" else 32.0,
        overhang=float(rng.uniform(0.4, 1.2)) if roof != "pagoda" else 1.8,
        ridge_along_x=bool(rng.random() < 0.7),
        bay_w=float(rng.uniform(2.0, 2.8)),
        window=(float(rng.uniform(0.8, 1.1)), float(rng.uniform(1.1, 1.7))),
        shutters=bool(rng.random() < 0.5),
        wall_roles=("walls_0", "walls_1"),
        timber_storeys=tuple(i for i in range(1, storeys) if rng.random() < 0.4),
        balcony_storeys=tuple(i for i in range(1, storeys) if rng.random() < 0.3 and roof != "pagoda"),
        chimneys=int(rng.integers(0, 3)),
        steps=int(rng.integers(0, 4)),
        porch=bool(rng.random() < 0.4),
        tower=footprint == "tower" or (footprint == "rectangle" and rng.random() < 0.25),
        tower_radius=float(rng.uniform(1.8, 2.6)),
        finishes=_finishes(
            walls_0=Finish(walls[0]),
            walls_1=Finish(walls[1]),
            gable=Finish(walls[1]),
            roof=Finish(pick(_ROOFS)),
            shutters=Finish(pick(_PAINT)),
            trim=Finish(pick(_WALLS)),
        ),
        lighting=random_lighting(rng),
        ground=Finish(pick(("grass", "gravel", "forest_floor"))),
    )
    if footprint == "tower":
        spec = replace(spec, storeys=max(2, storeys), roof="gable", chimneys=0)
    return spec


def build_random(seed: int, detail: bool = True) -> Scene:
    """The building `random:SEED` (see the module docstring for the train/test split; `detail` as in
    `build_preset`)."""
    return build_building(f"random:{seed}", random_spec(seed), seed % 16, detail)
