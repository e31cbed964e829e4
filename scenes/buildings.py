"""Assembling a textured building from a `BuildingSpec` (a small shape grammar).

The building is modelled in real metres (storeys of about 3 m) as a union of
closed solids: footprint wings (rectangle, L, U, cross) or a round tower,
storeys with optional jetties or setbacks, plinth, string courses, timber
framing, roofs, chimneys, a tower; then window and door openings are cut;
then fittings are added (glass, mullions, sills, shutters, doors, balconies,
porch, steps, columns). `build_building` turns it into a normalised `Scene`
(docs/conventions.md) with a textured ground.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from scenes.csg import SolidBuilder
from scenes.detail import detailed
from scenes.facade import Opening, balcony, cut_opening, fit_opening, quoins, timber_frame
from scenes.model import Lighting, Scene
from scenes.normalise import make_ground, normalise_parts
from scenes.roofs import Rect, chimney, cone_roof, eave_brackets, eave_skirt, flat_roof, gable_roof, hip_roof
from scenes.solids import WallFrame, box, hull, outline, prism, regular_polygon, wall_frames
from scenes.surface import Finish, textured_parts

TOWER_SIDES = 12
"""Facets of a round tower (windows sit on flat facets)."""
GATE_W = 2.4
"""Width of the gate through a courtyard's front wing, metres (a gap: the plan stays one polygon)."""


@dataclass(frozen=True)
class BuildingSpec:
    """Everything that decides a building's shape and look (lengths in real metres)."""

    footprint: Literal["rectangle", "L", "U", "cross", "tower", "courtyard"] = "rectangle"
    """Plan: one wing, L / U / cross of wings, a round tower, or wings round a court (roof hip or flat)."""
    width: float = 12.0
    """Main wing length along x."""
    depth: float = 8.0
    """Main wing depth along y."""
    wing: float = 6.0
    """How far side wings reach beyond the main wing (L, U, cross)."""
    storeys: int = 2
    """Number of storeys."""
    storey_h: float = 3.0
    """Height of one storey."""
    plinth_h: float = 0.6
    """Height of the stone plinth (ground floor level)."""
    jetty: float = 0.0
    """Outward growth of each storey over the one below (negative: setback, as in a pagoda)."""
    roof: Literal["gable", "hip", "flat", "pagoda"] = "gable"
    """Roof type; 'pagoda' puts an eave skirt at every storey and a hip roof on top."""
    pitch_deg: float = 40.0
    """Roof pitch."""
    overhang: float = 0.6
    """Roof overhang beyond the walls."""
    ridge_along_x: bool = True
    """Ridge of the main wing's gable roof along x (else along y: gable facing the front)."""
    bay_w: float = 2.5
    """Spacing of window bays along a wall."""
    window: tuple[float, float] = (1.0, 1.5)
    """Window width and height."""
    shutters: bool = False
    """Shutters beside every window."""
    wall_roles: tuple[str, ...] = ("walls",)
    """Finish role of each storey's walls (the last repeats upwards)."""
    quoin_storeys: tuple[int, ...] = ()
    """Storeys with dressed corner stones (quoins)."""
    timber_storeys: tuple[int, ...] = ()
    """Storeys with half-timber framing."""
    balcony_storeys: tuple[int, ...] = ()
    """Storeys with a balcony on the front wall (its windows become glazed doors)."""
    balcony_depth: float = 1.2
    """How far balconies project."""
    balcony_all_round: bool = False
    """Balconies on every long enough wall of the balcony storeys, not only the front."""
    chimneys: int = 1
    """Number of chimneys."""
    steps: int = 3
    """Steps up to the front door (0: none)."""
    porch: bool = False
    """A small roof on posts over the front door."""
    tower: bool = False
    """A round tower at the front-right corner."""
    tower_radius: float = 2.4
    """Radius of the round tower."""
    platform: int = 0
    """Tiers of a stepped stone platform under the building (temple)."""
    colonnade: bool = False
    """Columns around the ground storey, under the first eave (pagoda roofs)."""
    ruined: bool = False
    """Break away a corner of the walls and roof."""
    finishes: dict[str, Finish] = field(default_factory=dict)
    """Finish of every role used (walls roles, plinth, trim, reveal, glass, door, ...)."""
    lighting: Lighting = field(default_factory=Lighting)
    """Sun and sky."""
    ground: Finish = field(default_factory=lambda: Finish("grass"))
    """Finish of the ground plane."""


def wings(spec: BuildingSpec) -> list[Rect]:
    """The footprint as axis-aligned rectangles (x0, y0, x1, y1), front wall at y = y0."""
    w, d, reach = spec.width / 2, spec.depth / 2, spec.wing
    arm = 0.75 * spec.depth
    main = (-w, -d, w, d)
    if spec.footprint == "tower":
        return []
    if spec.footprint == "L":
        return [main, (w - arm, -d, w, d + reach)]
    if spec.footprint == "U":
        return [main, (-w, -d, -w + arm, d + reach), (w - arm, -d, w, d + reach)]
    if spec.footprint == "cross":
        return [main, (-arm / 2, -d - reach, arm / 2, d + reach)]
    if spec.footprint == "courtyard":  # back wing, front wing either side of the gate, side wings
        b, g, r = 3 * d + reach, GATE_W / 2, w - arm
        return [(-w, d + reach, w, b), (-w, -d, -g, d), (g, -d, w, d), (-w, -d, -r, b), (r, -d, w, b)]
    return [main]


def _grow(rect: Rect, g: float) -> Rect:
    return rect[0] - g, rect[1] - g, rect[2] + g, rect[3] + g


class _Assembly:
    """One building being assembled: storey heights, outlines and keep-out zones."""

    def __init__(self, spec: BuildingSpec, seed: int, builder: SolidBuilder | None = None) -> None:
        self.spec, self.rng, self.b = spec, np.random.default_rng(seed), builder or SolidBuilder()
        self.rects = wings(spec)
        self.base = 0.5 * spec.platform
        self.z = [self.base + spec.plinth_h + i * spec.storey_h for i in range(spec.storeys + 1)]
        self.z[0] = self.base
        self.tower_c = (0.0, 0.0) if spec.footprint == "tower" else (spec.width / 2, -spec.depth / 2)
        self.has_tower = spec.tower or spec.footprint == "tower"
        self.openings: list[Opening] = []
        self.door: tuple[WallFrame, float] | None = None

    def grow(self, i: int) -> float:
        return self.spec.jetty * i

    def frames(self, i: int) -> list[WallFrame]:
        return [f for poly in outline(self.rects, self.grow(i)) for f in wall_frames(poly, self.z[i])]

    def blocked(self, f: WallFrame, u: float, reach: float) -> bool:
        """Whether a detail at u on wall f would run into the tower."""
        if not self.has_tower or self.spec.footprint == "tower":
            return False
        p = f.point(u, 0.0, 0.0)
        return math.hypot(p[0] - self.tower_c[0], p[1] - self.tower_c[1]) < self.spec.tower_radius + reach

    def structure(self) -> None:
        s, b = self.spec, self.b
        for t in range(s.platform):
            g = (s.platform - t) * 0.7 + 0.5
            for poly in outline(self.rects or [(-s.tower_radius,) * 2 + (s.tower_radius,) * 2], g):
                b.add(prism(poly, 0.5 * t, 0.5 * (t + 1)), "plinth")
        if self.rects:
            for poly in outline(self.rects, 0.12):
                b.add(prism(poly, self.base, self.base + s.plinth_h), "plinth")
        for i in range(s.storeys if self.rects else 0):
            role = s.wall_roles[min(i, len(s.wall_roles) - 1)]
            for poly in outline(self.rects, self.grow(i)):
                b.add(prism(poly, self.z[i] - (0.05 if i else 0.0), self.z[i + 1]), role)
            if i > 0:
                for poly in outline(self.rects, self.grow(i) + 0.1):
                    b.add(prism(poly, self.z[i] - 0.14, self.z[i] + 0.08), "trim")
            if i in s.quoin_storeys:
                for f in self.frames(i):
                    quoins(b, f, self.z[i + 1] - self.z[i])
            if i in s.timber_storeys:
                for f in self.frames(i):
                    n = max(1, int(f.length / s.bay_w))
                    timber_frame(
                        b,
                        f,
                        self.z[i + 1] - self.z[i],
                        [f.length * k / n for k in range(n + 1)],
                        self._sill(i) - self.z[i] - 0.15,
                    )
        if self.rects:
            self.roof()

    def _sill(self, i: int) -> float:
        return self.z[i] + (self.spec.plinth_h if i == 0 else 0.0) + 0.9

    def roof(self) -> None:
        s, b = self.spec, self.b
        top, g = self.z[-1], self.grow(s.storeys - 1)
        if s.roof == "gable":
            for k, rect in enumerate(self.rects):
                gable_roof(b, _grow(rect, g), top, s.pitch_deg, s.overhang, s.ridge_along_x == (k == 0))
        elif s.roof == "hip":
            for rect in self.rects:
                hip_roof(b, _grow(rect, g), top, s.pitch_deg, s.overhang)
        elif s.roof == "flat":
            flat_roof(b, outline(self.rects, g + 0.25), outline(self.rects, g - 0.15), top)
        else:
            main = self.rects[0]
            for i in range(1, s.storeys):
                eave_skirt(
                    b,
                    _grow(main, self.grow(i - 1)),
                    _grow(main, self.grow(i)),
                    self.z[i],
                    0.6 * s.pitch_deg,
                    s.overhang,
                )
            hip_roof(b, _grow(main, g), top, s.pitch_deg, s.overhang)
            eave_brackets(
                b, _grow(main, g + 0.5 * s.overhang), top - s.overhang * math.tan(math.radians(s.pitch_deg))
            )

    def roof_top(self) -> float:
        s = self.spec
        if not self.rects:
            return self.z[-1]
        half = min(s.depth, s.width) / 2 + self.grow(s.storeys - 1)
        rise = 0.8 if s.roof == "flat" else half * math.tan(math.radians(s.pitch_deg))
        return self.z[-1] + rise

    def tower(self) -> None:
        s, b = self.spec, self.b
        levels = s.storeys + (0 if s.footprint == "tower" else 1)
        z_top = self.base + s.plinth_h + levels * s.storey_h
        ring = regular_polygon(self.tower_c, s.tower_radius, TOWER_SIDES)
        b.add(
            prism(
                regular_polygon(self.tower_c, s.tower_radius + 0.15, TOWER_SIDES),
                self.base,
                self.base + s.plinth_h,
            ),
            "plinth",
        )
        b.add(prism(ring, self.base, z_top), s.wall_roles[0])
        for i in range(1, levels):
            zi = self.base + s.plinth_h + i * s.storey_h
            b.add(
                prism(regular_polygon(self.tower_c, s.tower_radius + 0.1, TOWER_SIDES), zi - 0.14, zi + 0.08),
                "trim",
            )
        cone_roof(b, self.tower_c, s.tower_radius, TOWER_SIDES, z_top, 55.0, 0.5)
        for i in range(levels):
            zi = self.base + (s.plinth_h + 0.9 if i == 0 else s.plinth_h + i * s.storey_h + 0.9)
            for k, f in enumerate(wall_frames(ring, self.base)):
                mid = f.point(f.length / 2, 1.0, 0.0)
                if (k + i) % 2 or any(
                    r[0] - 0.5 < mid[0] < r[2] + 0.5 and r[1] - 0.5 < mid[1] < r[3] + 0.5 for r in self.rects
                ):
                    continue
                if i == 0 and s.footprint == "tower" and k == TOWER_SIDES - 4:
                    self._door(f, f.length / 2)
                    continue
                w = min(s.window[0], 0.55 * f.length)
                self.openings.append(Opening(f, f.length / 2, 0.8 * w, zi, zi + s.window[1]))

    def _door(self, f: WallFrame, u: float) -> None:
        s = self.spec
        z0 = self.base + s.plinth_h
        self.openings.append(Opening(f, u, 1.2, z0, z0 + 2.3, door=True, reach=0.4))
        self.door = (f, u)

    def plan_openings(self) -> None:
        s = self.spec
        front = self._front()
        for i in range(s.storeys if self.rects else 0):
            for f in self.frames(i):
                n = max(1, int(f.length / s.bay_w))
                for k in range(n):
                    u = (k + 0.5) * f.length / n
                    if self.blocked(f, u, s.window[0] + 0.6):
                        continue
                    if i == 0 and f is front and k == n // 2:
                        self._door(f, u)
                        continue
                    glazed_door = i in s.balcony_storeys and self._has_balcony(f)
                    z0 = self.z[i] + 0.02 if glazed_door else self._sill(i)
                    z1 = z0 + (2.2 if glazed_door else s.window[1])
                    self.openings.append(
                        Opening(f, u, s.window[0], z0, z1, shutters=s.shutters and not glazed_door)
                    )

    def _has_balcony(self, f: WallFrame) -> bool:
        s = self.spec
        if s.balcony_all_round:
            return f.length >= 0.5 * min(s.width, s.depth)
        return f.n[1] < -0.9 and f.length >= 0.5 * s.width

    def _front(self) -> WallFrame | None:
        frames = self.frames(0) if self.rects else []
        facing = [f for f in frames if f.n[1] < -0.9]
        return max(facing, key=lambda f: f.length) if facing else None

    def fittings(self) -> None:
        s, b = self.spec, self.b
        for o in self.openings:
            fit_opening(b, o)
        for i in s.balcony_storeys:
            for f in self.frames(i):
                if self._has_balcony(f):
                    balcony(b, f, 0.08 * f.length, 0.92 * f.length, self.z[i], s.balcony_depth)
        if self.door is not None:
            self._entrance(*self.door)
        if s.colonnade and self.rects:
            self._colonnade()

    def _entrance(self, f: WallFrame, u: float) -> None:
        s, b = self.spec, self.b
        rise = self.base + s.plinth_h - float(f.origin[2])
        reach = 0.12
        if s.steps and rise > 0.05 and not s.platform:
            for k in range(s.steps):
                out = reach + (s.steps - k) * 0.34
                b.add(
                    f.box(
                        (u - 1.0 - 0.1 * (s.steps - k), u + 1.0 + 0.1 * (s.steps - k)),
                        (-0.1, out),
                        (0.0, rise * (k + 1) / s.steps),
                    ),
                    "steps",
                )
        if s.porch:
            top = rise + 2.3 + 0.55
            plate = [
                f.point(uu, nn, zz)
                for uu in (u - 1.3, u + 1.3)
                for (nn, zz) in ((-0.05, top), (-0.05, top + 0.18), (1.9, top - 0.55), (1.9, top - 0.37))
            ]
            b.add(hull(np.array(plate)), "roof")
            for side in (-1, 1):
                b.add(
                    f.box((u + side * 1.1 - 0.09, u + side * 1.1 + 0.09), (1.55, 1.73), (0.0, top - 0.45)),
                    "beams",
                )

    def _colonnade(self) -> None:
        s, b = self.spec, self.b
        x0, y0, x1, y1 = _grow(self.rects[0], 1.3)
        z_top = self.z[1] - s.overhang * math.tan(math.radians(0.6 * s.pitch_deg)) + 0.05
        spots = set()
        for a, c, count in (((x0, y0), (x1, y0), 6), ((x0, y1), (x1, y1), 6), ((x0, y0), (x0, y1), 4),
                            ((x1, y0), (x1, y1), 4)):
            for k in range(count + 1):
                t = k / count
                spots.add((round(a[0] + t * (c[0] - a[0]), 6), round(a[1] + t * (c[1] - a[1]), 6)))
        for x, y in sorted(spots):
            b.add(prism(regular_polygon((x, y), 0.24, 12), self.base, z_top), "columns")
            b.add(box((x - 0.32, y - 0.32, self.base), (x + 0.32, y + 0.32, self.base + 0.25)), "trim")
            b.add(box((x - 0.3, y - 0.3, z_top - 0.35), (x + 0.3, y + 0.3, z_top - 0.1)), "trim")
        for a, c in (((x0, y0), (x1, y0)), ((x0, y1), (x1, y1)), ((x0, y0), (x0, y1)), ((x1, y0), (x1, y1))):
            lo, hi = np.minimum(a, c) - 0.2, np.maximum(a, c) + 0.2
            b.add(box((lo[0], lo[1], z_top - 0.55), (hi[0], hi[1], z_top - 0.3)), "columns")

    def front_stairs(self) -> None:
        s = self.spec
        if not s.platform:
            return
        x0, y0, _, _ = _grow(
            self.rects[0] if self.rects else (-s.tower_radius,) * 2 + (s.tower_radius,) * 2,
            s.platform * 0.7 + 0.5,
        )
        count = 3 * s.platform
        for k in range(count):
            y = y0 - (count - k) * 0.35
            self.b.add(box((-2.0, y, 0.0), (2.0, y0 + 0.05, (k + 1) * self.base / count)), "steps")
        x0, y0, x1, y1 = _grow(
            self.rects[0] if self.rects else (-s.tower_radius,) * 2 + (s.tower_radius,) * 2,
            s.platform * 0.7 + 0.3,
        )
        for f in wall_frames(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), self.base):
            gap = (f.length / 2 - 2.3, f.length / 2 + 2.3) if f.n[1] < -0.9 else (0.0, 0.0)
            for k in range(int(f.length / 0.6) + 1):
                u = min(k * 0.6, f.length - 0.08)
                if not gap[0] - 0.1 < u < gap[1]:
                    self.b.add(f.box((u, u + 0.1), (-0.05, 0.05), (0.0, 0.9)), "trim")
            for lo, hi in ((0.0, gap[0]), (gap[1], f.length)) if gap[1] else ((0.0, f.length),):
                self.b.add(f.box((lo, hi), (-0.07, 0.07), (0.82, 0.95)), "trim")

    def chimneys(self) -> None:
        s = self.spec
        if not self.rects or s.chimneys == 0:
            return
        top = self.roof_top() + (0.3 if s.ruined else 1.1)
        x0, y0, x1, y1 = self.rects[0]
        for k in range(s.chimneys):
            x = x0 + (k + 0.5 + 0.3) / (s.chimneys + 0.6) * (x1 - x0) * 0.9
            y = (y0 + y1) / 2 + 0.22 * (y1 - y0)
            chimney(self.b, x, y, self.z[-1] - 0.5, top)

    def ruin(self) -> None:
        """Break away the front-left top corner in jagged steps.

        Each cut is a slanted block reaching far out past the corner and up into
        the sky, so every broken face opens onto the outside (no hidden pits).
        """
        x0, y0 = -self.spec.width / 2, -self.spec.depth / 2
        top = self.z[-1]
        for k, (reach, drop) in enumerate(((1.2, 3.2), (2.4, 1.9), (3.6, 0.9))):
            inner = [
                (
                    x0 + reach * self.rng.uniform(0.7, 1.3),
                    y0 + reach * self.rng.uniform(0.7, 1.3),
                    top - drop * self.rng.uniform(0.8, 1.2),
                )
                for _ in range(4)
            ]
            far = [
                (x0 - 4.0, y0 - 4.0, top + 12.0),
                (x0 + reach, y0 - 4.0, top + 12.0),
                (x0 - 4.0, y0 + reach, top + 12.0),
                (x0 - 4.0, y0 - 4.0, top - drop),
            ]
            self.b.cut(hull(np.array(inner + far)), "broken")


def assemble(spec: BuildingSpec, seed: int, builder: SolidBuilder | None = None) -> SolidBuilder:
    """The solids of `spec` added to `builder` (a new one if None), in metres; returns the builder."""
    a = _Assembly(spec, seed, builder)
    a.structure()
    if a.has_tower:
        a.tower()
    a.chimneys()
    a.front_stairs()
    a.plan_openings()
    for o in a.openings:
        cut_opening(a.b, o)
    a.fittings()
    if spec.ruined:
        a.ruin()
    return a.b


def textured_scene(name: str, triangles: dict[str, np.ndarray], spec: BuildingSpec, seed: int,
                   detail: bool = True) -> Scene:
    """The normalised `Scene` of `triangles` with the finishes, ground and light of `spec`; `detail`: each
    part's texture baked with unique surface detail (`scenes.detail`), else the tiled textures alone."""
    parts = textured_parts(triangles, spec.finishes, seed)
    lo = np.min([p.vertices.min(0) for p in parts], axis=0)
    hi = np.max([p.vertices.max(0) for p in parts], axis=0)
    ground = make_ground(spec.ground, seed, center=(lo + hi)[:2] / 2, half_m=3.2 * float(np.max(hi - lo)))
    parts = detailed(parts + [ground], f"{name} {seed}") if detail else parts + [ground]
    return Scene(name, normalise_parts(parts), spec.lighting)


def build_building(name: str, spec: BuildingSpec, seed: int = 0, detail: bool = True) -> Scene:
    """The normalised, textured `Scene` of `spec` (seeded by `seed`; `detail` as in `textured_scene`)."""
    return textured_scene(name, assemble(spec, seed).triangles(), spec, seed, detail)
