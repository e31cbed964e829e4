"""The axes of `nbv ablate`: each a list of levels, one setting changed around the reference render.

A level is a label and the render settings it overrides (`render.settings`
field names; `lighting.*` and `sensor.*` reach the nested settings). The level
with no override is the reference (today's defaults), shared by every axis, so
it is measured once per building and seed. Axes marked `lighting` are also
scored by greedy Bag of Views planning (the paper warns that SIFT makes the
Bag of Views sensitive to lighting).

A run's units (`units`) are the reference and every other level, per building
and seed; each keeps its result where `unit_path` says.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from render.settings import RenderSettings

if TYPE_CHECKING:
    from nbv.experiments.ablate import AblateConfig

REFERENCE = "reference"
"""Axis and level name of the reference setting's own measurement."""


@dataclass(frozen=True)
class Level:
    """One setting of an axis: its label and the render settings it changes (none: the reference)."""

    label: str
    overrides: tuple[tuple[str, Any], ...] = ()

    @property
    def is_reference(self) -> bool:
        """True for the level that changes nothing."""
        return not self.overrides


@dataclass(frozen=True)
class Axis:
    """A rendering knob and its levels, in plotting order."""

    name: str
    title: str
    levels: tuple[Level, ...]
    lighting: bool = False


def _levels(field: str, values: dict[str, Any], reference: str) -> tuple[Level, ...]:
    """Levels of one field: label -> value, the label `reference` being today's default (no override)."""
    return tuple(Level(label, () if label == reference else ((field, value),))
                 for label, value in values.items())


AXES: dict[str, Axis] = {axis.name: axis for axis in (
    Axis("spp", "samples per pixel", _levels("spp", {"1": 1, "4": 4, "16": 16, "64": 64}, "16")),
    Axis("denoiser", "OIDN denoiser (box filter) at low spp",
         (Level("off, 16 spp"),
          *(Level(f"oidn, {spp} spp", (("denoiser", "oidn"), ("spp", spp))) for spp in (1, 4, 16)))),
    Axis("resolution", "resolution scale (field of view kept)",
         _levels("resolution_scale", {"0.5x": 0.5, "1x": 1.0, "2x": 2.0}, "1x")),
    Axis("pixel_filter", "pixel reconstruction filter",
         _levels("pixel_filter", {"gaussian": None, "box": "box", "mitchell": "mitchell"},
                 "gaussian")),
    Axis("max_depth", "light-path depth", _levels("max_depth", {"2 (direct)": 2, "4": 4, "8": 8}, "4")),
    Axis("light_mode", "lights", _levels("lighting.light_mode", {"sun and sky": "sun_and_sky",
                                                                 "overcast": "overcast",
                                                                 "hard sun": "hard_sun"}, "sun and sky"),
         lighting=True),
    Axis("sun_elevation", "sun elevation, degrees",
         _levels("lighting.sun_elevation_deg", {"20": 20.0, "50": None, "80": 80.0}, "50"), lighting=True),
    Axis("sky_model", "sky model", _levels("lighting.sky_model", {"uniform": "uniform", "sunsky": "sunsky"},
                                           "uniform"), lighting=True),
    Axis("exposure", "exposure, stops",
         _levels("sensor.exposure_stops", {"-2": -2.0, "0": 0.0, "+2": 2.0}, "0")),
    Axis("sensor_noise", "Poisson-Gaussian sensor noise (shot / read)",
         (Level("none"), Level("0.001 / 0.002", (("sensor.shot_noise", 0.001), ("sensor.read_noise", 0.002))),
          Level("0.01 / 0.01", (("sensor.shot_noise", 0.01), ("sensor.read_noise", 0.01))))),
    Axis("jpeg", "JPEG quality", _levels("sensor.jpeg_quality",
                                         {"lossless": None, "90": 90, "50": 50, "20": 20}, "lossless")),
    Axis("texture_scale", "texture resolution scale",
         _levels("texture_scale", {"1": 1.0, "0.5": 0.5, "0.25": 0.25}, "1")),
    Axis("motion_blur", "motion blur, metres of travel",
         _levels("motion_blur_m", {"0": 0.0, "0.02": 0.02, "0.1": 0.1}, "0")),
)}
"""Every axis `nbv ablate` knows, by name (`--axis NAME`)."""


def apply_level(settings: RenderSettings, level: Level) -> RenderSettings:
    """`settings` with the level's overrides (validated by the settings' own checks)."""
    changed = settings
    for path, value in level.overrides:
        head, _, leaf = path.rpartition(".")
        if head:
            nested = getattr(changed, head)
            changed = replace(changed, **{head: replace(nested, **{leaf: value})})
        else:
            changed = replace(changed, **{leaf: value})
    return changed


def check_axes(names: tuple[str, ...]) -> None:
    """Refuse (ValueError) an empty axis list or an unknown axis name."""
    if not names:
        raise ValueError("an ablation needs at least one --axis")
    unknown = [n for n in names if n not in AXES]
    if unknown:
        raise ValueError(f"unknown axis {unknown[0]!r} (choose from {', '.join(AXES)})")


@dataclass(frozen=True)
class Unit:
    """One measurement: a level of an axis (or the reference) on one building with one seed."""

    scene: str
    axis: str
    level: Level
    seed: int

    @property
    def name(self) -> str:
        """A readable name, e.g. `medieval_tavern / spp=4 / seed 0`."""
        return f"{self.scene} / {self.axis}={self.level.label} / seed {self.seed}"


def _slug(text: str) -> str:
    return "".join(c if c.isalnum() or c in "-." else "_" for c in text)


def units(config: AblateConfig) -> list[Unit]:
    """Every unit of the run: per building and seed, the reference, then each axis's other levels."""
    out = []
    for scene in config.scenes:
        for seed in config.seeds:
            out.append(Unit(scene, REFERENCE, Level(REFERENCE), seed))
            out += [Unit(scene, name, level, seed) for name in config.axes
                    for level in AXES[name].levels if not level.is_reference]
    return out


def unit_path(folder: Path, unit: Unit) -> Path:
    """Where `unit`'s result JSON lives under `folder`."""
    return folder / _slug(unit.scene) / _slug(unit.axis) / f"{_slug(unit.level.label)}-seed{unit.seed}.json"
