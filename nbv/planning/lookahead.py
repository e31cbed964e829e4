"""The teacher's look-ahead on measured depth (`--planner lookahead`; issue 26's depth option, round 23).

The privileged teacher of training (`nbv.rl.expert`) scores each of 125 orbit steps (an azimuth step of up
to 60 degrees, an absolute radius and elevation: the default preset's action space) by the true surface
samples that it and the next two steps the same way would be the first to see, discounted by 0.9 a step,
less a flight cost a metre along the viewing shell. This planner runs the same scoring
(`expert_scores`) at flight time on what a depth camera measures instead: an occupancy grid over the
target's bounds (`nbv.recon.occupancy`, as the infogain planner's), fused from the depth image of every
view flown. A voxel counts as seen once it is known (free or occupied); a view sees the unknown voxels its
rays reach before an occupied one (`OccupancyGrid.reached`); a step scores 100 x the share of the grid's
voxels its views are the first to reach. It reads depth and the poses flown, never the mesh (but the
target's bounding box, as infogain does), so issue 26 reports it apart from the policies that read images
alone.

The grid, the rays and the flight weight were chosen on the validation buildings
(paper_results/selection/round23, section 4): 48 voxels along the longest side, `LOOKAHEAD_RAYS` rays
across the image (every 4th pixel at 160 x 120), 0.07 a metre: over six start views 4.5 points more
coverage than the tuned ring there, at least 0.4 more on every building, in 1.39x its metres (0.05 a
metre flew 1.51x on the second three). `lookahead:W` flies another flight weight W (coverage points a
metre). Held out, scored once (paper_results/online/acceptance, `nbv online --depth-options lookahead`):
4.2 points above the ring in 1.13x its metres, 5.1 under it on the walled compound.

`lookahead-stereo` runs the same look-ahead on what a camera alone measures: at each view the UAV takes a
second frame `STEREO_BASELINE_M` along its orbit (a step sideways, as a frame of its flight video), and
plane-sweep stereo between the two (`nbv.recon.stereo`) gives both frames' depth where it finds a consistent
match; only that depth is fused, the rest stays unknown. It reads images and the poses flown (and the target's
box), so it is held to every check of the policies, the blank-images one included. Held out, scored once on
the teacher's steps (paper_results/online/stereo in git at e7f44fa): 3.8 points above the ring in 1.26x its
metres, 31.3 lost with blank frames, 3.4 under the ring on the walled compound. Rounds 26, 27, 29 and 30
(paper_results/selection, docs/rl.md) tried the options below on the validation buildings, none passing more
checks then (`partners`, `agree`, `votes`, `frontier`, `patience`, `horizon`, `next_to_free`, `spacing_m`,
`sight_deg`; round 38's `pace`). Round 28 chose a pilot's orbit's forward steps (`STEREO_FORWARD`). Round 31
found what the grid cannot see: an occupied voxel holds every face of the surface in it, so with `sides` a
view also gains for each occupied voxel it would meet from a side never measured (`OccupancyGrid.sighted`).
The constants below record each setting chosen since, with its round: the sides' worth and a battery's hinge
(`STEREO_SIDES`, `STEREO_HINGE`, `STEREO_PER_VIEW`), a steep band that measures no side (`STEREO_STEEP`), the
route (`STEREO_ROUTE`), the grid's votes on the route (`STEREO_VOTES`). Held out, scored once before the votes
(paper_results/online/stereo at 781c773): 5.2 points above the ring in 1.42x its metres, 4.5 above random
views on the courtyard `family:15` (the bar is 5), five of six checks. The options measured and not adopted
stay one argument away (`LookaheadOptions`, docs/rl.md).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from nbv.flight.path import shell_path
from nbv.planning.base import Planner
from nbv.planning.infogain import target_grid
from nbv.planning.route import RouteSearch, view_key
from nbv.planning.step_rules import ruled_out
from nbv.recon.config import OccupancyConfig
from nbv.recon.occupancy import OCCUPIED, SECTORS, UNKNOWN, OccupancyGrid
from nbv.recon.stereo import StereoConfig, agreed_depth, box_stereo_depth, grayscale, within_box
from nbv.rl.env import action_to_viewpoint
from nbv.rl.expert import CANDIDATES, best_action, expert_scores
from nbv.rl.presets import ORBIT_STEP
from render.viewpoint import Viewpoint, viewpoint_to_c2w

if TYPE_CHECKING:
    from nbv.planning.config import PlanSettings
    from nbv.planning.world import PlanningWorld

LOOKAHEAD_GRID = 48
"""Voxels along the longest side of the target's padded bounds (round 23: 32 blurred a courtyard)."""
LOOKAHEAD_RAYS = 40
"""Rays across the image's width that a look-ahead view casts (and its height in proportion)."""
LOOKAHEAD_FLIGHT = 0.07
"""The flight cost, coverage points (of the grid's voxels) a metre along the viewing shell."""
HORIZON, DISCOUNT = 3, 0.9
"""Views scored ahead per candidate step, and the weight a step further (the teacher's defaults)."""
STEREO_FLIGHT = 0.1
"""`lookahead-stereo`'s flight cost a metre (round 25, validation buildings: of 0.07 to 0.4, all passing four
of six checks, the largest margin over the tuned ring, +3.8 points)."""
STEREO_BASELINE_M = 0.25
"""How far along the orbit `lookahead-stereo` takes each view's second frame, metres (chosen with the sweep's
settings on four training buildings, paper_results/selection/round25/stereo_depth)."""
STEREO_PARTNERS = ("back",)
"""Where `lookahead-stereo` takes each view's second frames, `STEREO_BASELINE_M` from it (`PARTNER_SIDES`)."""
STEREO_AGREE = 0
"""How many pairs must agree on a depth for `lookahead-stereo` to fuse it (0: every pair's depth is fused)."""
STEREO_FORWARD = True
"""`lookahead-stereo` steps as a pilot's orbit, always forward (round 28, validation buildings: five of six
checks, the first image-only planner to pass five; the teacher's steps either way passed four)."""
STEREO_SIDES = 1.0
"""`lookahead-stereo`'s worth of an occupied voxel met from a direction never measured, in unknown voxels
(`LookaheadOptions.sides`; round 31, validation buildings: with `STEREO_HINGE` five of six checks, the worst
building 0.4 under the ring against round 28's 0.6)."""
STEREO_HINGE = (13.0, 2.0)
"""`lookahead-stereo`'s battery hinge: metres of flight, then coverage points a metre more (`allowance_m`,
`excess`; round 31: without it the sides term flew 1.57x the ring's metres, with it 1.44x). Metres along the
viewing shell of the default preset's ranges (the tuned ring flies 9.0 m)."""
STEREO_PER_VIEW = 1.0
"""`lookahead-stereo`'s battery a view where that passes `STEREO_HINGE`'s metres (`battery_per_view_m`): 13 m
up to 13 views, 1 m a view past them (round 33, validation buildings: at 16 views 94.6 % against the fixed
battery's 94.2, the worst building nearer the ring and random views; round 32's 20 views likewise)."""
STEREO_STEEP = 60.0
"""`lookahead-stereo`'s steep band, degrees: a ray looking down more steeply measures no side
(`steep_deg`, `steep_measures` off; round 36 on the validation buildings, confirmed from start views never
flown in round 37: 0.28 points more coverage, the worst building 0.3 nearer the ring)."""
STEREO_ROUTE = True
"""`lookahead-stereo` plans every view still to take together, re-planned at each view (`route`; round 39,
validation buildings over nine start views: 95.32 % against 94.42, the worst building 0.96 above the ring
against 0.06 under, both courtyards up by 1.0 and 1.3)."""
STEREO_VOTES = True
"""`lookahead-stereo`'s grid weighs hits against passes, one vote an image (`votes`; round 51: a floater one
view's false match marks beside a silhouette is cleared by later views' rays; 95.22 % against 94.19 on four
fresh training courtyards, all four up, and five of six checks on the validation buildings)."""
PARTNER_SIDES = ("back", "forward", "up")
"""Back or forward along the view's orbit, or up its meridian."""
BANDS = (1, 2, 3)
"""The vertical bands a side may be told apart by (`LookaheadOptions.bands`)."""
DEPTH_SOURCES = ("camera", "stereo")
"""Where the look-ahead's depth comes from: a depth camera, or plane-sweep stereo on two frames a view."""
FORWARD_STEP = 2 / 13
"""With `forward`, the steps' azimuth advance is half to all of this share of a turn (27.7 to 55.4 degrees a
view: the tuned ring's step and the two rings' both inside; round 16's forward action space)."""


@dataclass(frozen=True, kw_only=True)
class LookaheadOptions:
    """The look-ahead's variants, each flown on the validation buildings (rounds 24 to 29; the defaults are
    the teacher's, `forward` `lookahead-stereo`'s own, `STEREO_FORWARD`)."""

    distinct: bool = False
    """Never step onto a view already flown (else staying put may win where the flight costs more than the
    grid says is left)."""
    partners: tuple[str, ...] = STEREO_PARTNERS
    """With stereo, the sides of the view its second frames are taken on (`PARTNER_SIDES`), each swept with
    it."""
    agree: int = STEREO_AGREE
    """With stereo, 0 fuses every pair's depth of both its frames, N >= 1 only the view's depth that N pairs
    agree on (`agreed_depth`)."""
    votes: bool = False
    """The grid weighs hits against passes (`OccupancyConfig.votes`)."""
    frontier: int = 0
    """k > 0: a view sees only each ray's first k unknown voxels (`OccupancyGrid.reached`)."""
    allowance_m: float = 0.0
    """Metres of the flight before `excess` is charged (a battery's budget, the teacher's hinge,
    `nbv.rl.flight_cost`)."""
    excess: float = 0.0
    """Coverage points a metre more for the flight past `allowance_m`."""
    battery_per_view_m: float = 0.0
    """> 0: the battery grows with the view budget, to this many metres a view where that passes
    `allowance_m` (`battery`)."""
    patience: int = 0
    """n > 0: an unknown voxel that n views flown have reached without measuring it counts as seen (stereo
    leaves texture it cannot match unknown)."""
    horizon: int = HORIZON
    """The views scored ahead of each candidate step."""
    next_to_free: bool = False
    """A view sees only the unknown voxels it reaches that lie beside free space
    (`OccupancyGrid.frontier`)."""
    forward: bool = False
    """The steps are the `forward` action mode's (`nbv.rl.env.action_to_viewpoint`), each advancing the
    azimuth the same way by 27.7 to 55.4 degrees (`FORWARD_STEP`), as a pilot's orbit: no reversal, never
    standing still (though at 80 degrees and 1.5 m a 27.7-degree step is a 0.13 m arc, round 28)."""
    spacing_m: float = 0.0
    """> 0: never step to a camera position within this many metres (straight line) of a view flown (once
    every step would, the rule is dropped for that step)."""
    sight_deg: float = 0.0
    """> 0: never step to a view whose sight line (the direction from the aim point to its camera) lies
    within this many degrees of a view flown's, whatever its radius (once every step would, the rule is
    dropped for that step): at 80 degrees two views share a sight line within 15 degrees up to 97.5
    degrees of azimuth apart, so forward steps leave the top after one view (round 30)."""
    sides: float = 0.0
    """> 0: a view also gains this much (in unknown voxels) for each occupied voxel its rays would first
    meet from a direction it was never measured from (`OccupancyGrid.sighted`; round 31): an occupied voxel
    holds every face of the surface in it, so the unknown-voxel gain alone cannot see that an eave's
    underside or a parapet's inner face was never in view."""
    steep_deg: float = 0.0
    """> 0, with `sides`: rays looking down more steeply than this many degrees are a direction of their own
    (`OccupancyGrid`'s `steep_deg`, set here alone: only the sides use it; round 35): a wall seen only from
    nearly overhead, at a grazing angle, still gains a view that meets it from the side."""
    sectors: int = 4
    """With `sides`, the horizontal directions a side is measured from: 4 quadrants or 8 sectors
    (`OccupancyGrid`'s `sectors`; round 45)."""
    padding_free: bool = False
    """The grid's padding (voxels wholly outside the target's bounds) is free at first (round 50)."""
    in_box: bool = False
    """With stereo, a depth whose point lies outside the target's bounds (grown by a voxel) is not fused
    (`within_box`; round 51)."""
    bands: int = 3
    """With `sides`, the vertical bands a side is told by: 3 (`sight_bin`'s down, level, up), 2 (down and
    level one: a wall seen from above is seen; round 48) or 1 (a sector's side, from any height; round 49)."""
    steep_measures: bool = True
    """With `steep_deg`, whether the steep band is a direction like the others (round 35) or measures no
    side (round 36): a steep ray then neither marks the side it meets as measured nor gains a view anything
    for it (`side_columns`)."""
    pace: bool = False
    """The battery is spent at an even pace (round 38): the hinge charges each leg's metres past its share,
    `battery(views)` times the legs flown with it over the flight's legs, not past the whole battery (else
    the first views may spend it, leaving the last to crowd at the shortest step)."""
    route: bool = False
    """With `forward`, every view still to take is chosen together, a route scored as one set and re-planned
    at each view (`nbv.planning.route`; round 39), not each step by its look-ahead of `horizon` views."""
    restarts: int = 0
    """With `route`, the route's search also improves this many routes of random steps, keeping the best
    (`RouteSearch.best`; round 40: 0.1 point more coverage, twice the planning time, not adopted)."""
    ceiling_deg: float = 0.0
    """> 0: every step's elevation is held to at most this many degrees, in the look-ahead as in the flight
    (round 36): a view from nearly overhead sees walls at a grazing angle."""

    def __post_init__(self) -> None:
        if self.frontier < 0 or self.patience < 0 or self.horizon < 1:
            raise ValueError(f"lookahead's frontier and patience are counts >= 0 (0: off) and its horizon "
                             f">= 1, got {self.frontier}, {self.patience}, {self.horizon}")
        if not all(0 <= x < float("inf") for x in (self.allowance_m, self.excess, self.battery_per_view_m)):
            raise ValueError(f"lookahead's flight allowance, excess weight and battery a view are finite and "
                             f">= 0, got {self.allowance_m}, {self.excess}, {self.battery_per_view_m}")
        if not 0 <= self.sides < float("inf") or not 0 <= self.steep_deg < 90 \
                or not 0 <= self.ceiling_deg <= 90 or self.sectors not in SECTORS or self.bands not in BANDS:
            raise ValueError(f"lookahead's weight of a side never measured is finite and >= 0, its steep "
                             f"band under 90 degrees, its ceiling at most 90 (0: none), its sectors 4 or "
                             f"8, its bands 1 to 3, got {self.sides}, {self.steep_deg}, {self.ceiling_deg}, "
                             f"{self.sectors}, {self.bands}")
        if not 0 <= self.spacing_m < float("inf") or not 0 <= self.sight_deg < 180:
            raise ValueError(f"lookahead's spacing is a finite distance >= 0 and its sight rule 0 to 180 "
                             f"degrees (0: none), got {self.spacing_m}, {self.sight_deg}")
        if self.route and (not self.forward or self.pace or self.masks):
            raise ValueError("lookahead's route plans forward steps (forward) and takes neither pace nor a "
                             "rule ruling steps out (distinct, spacing_m, sight_deg)")
        if self.restarts < 0 or (self.restarts and not self.route):
            raise ValueError(f"lookahead's restarts are a count >= 0 of random routes its route's search "
                             f"improves (route), got {self.restarts}")
        if not self.partners or not set(self.partners) <= set(PARTNER_SIDES) \
                or not 0 <= self.agree <= len(self.partners):
            raise ValueError(f"lookahead-stereo's partners are sides from {PARTNER_SIDES} and agree 0 to "
                             f"their number, got {self.partners}, {self.agree}")

    def battery(self, views: int) -> float:
        """The metres flown before `excess` is charged on a flight of `views` views: `allowance_m`, or
        `battery_per_view_m` a view where that is more."""
        return max(self.allowance_m, self.battery_per_view_m * views)

    def hinge(self, views: int, flown: int) -> tuple[float, float]:
        """The hinge's allowance for the next leg of a flight of `views` views with `flown` legs behind it,
        and how much it grows each leg after: with `pace` an even share of `battery` a leg, else all of it."""
        battery = self.battery(views)
        if not self.pace:
            return battery, 0.0
        share = battery / max(views - 1, 1)
        return share * (flown + 1), share

    @property
    def masks(self) -> bool:
        """Whether a rule (`distinct`, `spacing_m`, `sight_deg`) may rule steps out (`ruled_out`)."""
        return bool(self.distinct or self.spacing_m or self.sight_deg)


class LookaheadPlanner(Planner):
    """The teacher's look-ahead on an occupancy grid fused from the depth flown (module docstring)."""

    name = "lookahead"

    def __init__(self, flight: float = LOOKAHEAD_FLIGHT, grid: int = LOOKAHEAD_GRID,
                 rays: int = LOOKAHEAD_RAYS, default_views: int = 13, depth: str = "camera",
                 blank_images: bool = False, options: LookaheadOptions = LookaheadOptions()) -> None:
        """The flight weight a metre, the grid's voxels along its longest side, the rays across the image;
        `depth`: one of `DEPTH_SOURCES`; `blank_images`: with stereo, every captured frame replaced by a
        blank one (the evaluation's test that it looks); `options`: the variants (`LookaheadOptions`)."""
        if not 0 <= flight < float("inf") or min(grid, rays) < 1 or depth not in DEPTH_SOURCES:
            raise ValueError(f"lookahead needs a finite flight weight >= 0, grid >= 1, rays >= 1 and depth "
                             f"from {DEPTH_SOURCES}, got {flight}, {grid}, {rays}, {depth!r}")
        self.flight, self.grid, self.rays, self.default_views = flight, grid, rays, default_views
        self.depth, self.blank_images, self.options = depth, blank_images, options
        if depth == "stereo":
            self.name = "lookahead-stereo"

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """The start view, then each next one the orbit step whose look-ahead on the grid scores best."""
        camera, center, options = world.camera, world.target.center(), self.options
        stride = max(1, round(camera.width / self.rays))
        occupancy = OccupancyConfig(grid_resolution=self.grid, gain_ray_stride=stride, votes=options.votes)
        grid = target_grid(world.target, occupancy, options.steep_deg, options.sectors, options.padding_free)
        steps = replace(world.env, action_mode="forward", relative_step=FORWARD_STEP) if options.forward \
            else replace(world.env, action_mode="orbit", relative_step=ORBIT_STEP)

        seen: dict[tuple[float, float, float], np.ndarray] = {}  # this step's views (the grid is fixed)
        voxels = grid.state.size

        def sees(view: Viewpoint) -> np.ndarray:
            key = view_key(view)
            if key not in seen:
                seen[key], sighted = grid.look(camera.K, viewpoint_to_c2w(view, center), camera.width,
                                               camera.height, stride, options.frontier, bool(options.sides))
                if options.next_to_free:
                    seen[key] &= edge
                if options.sides:  # then (occupied voxel, direction) items: `side_items`
                    seen[key] = np.concatenate([seen[key], sighted[occupied][:, columns].any(-1).reshape(-1)])
            return seen[key]

        def step(action: np.ndarray, view: Viewpoint) -> Viewpoint:
            reached = action_to_viewpoint(action, view, steps)
            return replace(reached, elevation=min(reached.elevation, ceiling)) if options.ceiling_deg \
                else reached

        view, chosen, edge, occupied, route = world.start, [world.start], None, None, None
        columns, ceiling = side_columns(grid, options), np.radians(options.ceiling_deg)
        looked = np.zeros(voxels, np.uint16)  # views flown that reached each voxel, still unknown
        count = self.view_count(views)
        for left in range(count - 1, 0, -1):
            self.measure(world, grid, view)
            seen.clear()
            edge = grid.frontier() if options.next_to_free else None
            occupied = np.flatnonzero(grid.state.reshape(-1) == OCCUPIED) if options.sides else None
            known = grid.state.reshape(-1) != UNKNOWN
            if options.patience:
                looked += sees(view)[:voxels]
                known |= looked >= options.patience
            known, weights = side_items(grid, occupied, known, options.sides, columns)
            allowance, pace = options.hinge(count, len(chosen) - 1)
            flown = shell_path(chosen[0], chosen[1:]).total_m
            if options.route:
                search = RouteSearch(view, left, sees, known, weights, step, self.flight, voxels,
                                     flown_m=flown, allowance_m=allowance, excess=options.excess)
                route = search.best(route[1:] if route else None, options.restarts)
                view = search.next(route[0], view)
                chosen.append(view)
                continue
            scores = expert_scores(view, known, sees, step, self.flight, left, options.horizon, DISCOUNT,
                                   flown_m=flown, allowance_m=allowance, excess_weight=options.excess,
                                   pace_m=pace, weights=weights, total=voxels)
            if options.masks:
                ruled = np.array([ruled_out(step(action, view), chosen, options) for action in CANDIDATES])
                scores = np.where(ruled, -np.inf, scores) if not ruled.all() else scores
            view = step(best_action(scores), view)
            chosen.append(view)
        return chosen

    def measure(self, world: PlanningWorld, grid: OccupancyGrid, view: Viewpoint) -> None:
        """Fuse what the UAV measures at `view` into the grid (`measured`)."""
        center, stride = world.target.center(), OccupancyConfig().integrate_ray_stride
        for depth, at in self.measured(world, grid, view):
            grid.integrate(depth, world.camera.K, viewpoint_to_c2w(at, center), stride)

    def measured(self, world: PlanningWorld, grid: OccupancyGrid,
                 view: Viewpoint) -> list[tuple[np.ndarray, Viewpoint]]:
        """The depth images the UAV measures at `view`, each with the view it is from: the depth camera's
        image, or stereo depth of the view and each of its second frames (every pair swept apart; both
        frames' depth, or with `agree` only the view's depth that many pairs agree on)."""
        camera, center = world.camera, world.target.center()
        if self.depth == "camera":
            return [(world.source.render_depth(view), view)]

        def frame(v: Viewpoint) -> np.ndarray:
            return np.zeros((camera.height, camera.width)) if self.blank_images \
                else grayscale(world.source.render_rgb(v))

        image, pose = frame(view), viewpoint_to_c2w(view, center)
        fused, views = [], []
        for side in self.options.partners:
            partner = stereo_partner(view, side=side)
            fused.extend(box_stereo_depth(image, frame(partner), camera.K, pose,
                                          viewpoint_to_c2w(partner, center), grid.lower, grid.upper))
            views.extend((view, partner))
        if self.options.agree:
            fused, views = [agreed_depth(fused[::2], StereoConfig().consistency, self.options.agree)], [view]
        if self.options.in_box:
            lower, upper = world.target.bounds()
            fused = [within_box(d, camera.K, viewpoint_to_c2w(v, center), lower, upper, grid.voxel_size)
                     for d, v in zip(fused, views, strict=True)]
        return list(zip(fused, views, strict=True))


def side_items(grid: OccupancyGrid, occupied: np.ndarray, known: np.ndarray, sides: float,
               columns: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """The look-ahead's samples with `sides` > 0: the grid's voxels (`known`), then each `occupied` voxel's
    sides, the rows of sight bins `columns` (`side_columns`), known where it has been measured from any of a
    row's bins (`OccupancyGrid.sides`); and their worth (1 a voxel, `sides` a side). Without, `known` and
    None."""
    if not sides:
        return known, None
    masks = np.bitwise_or.reduce(np.left_shift(1, columns).astype(grid.sides.dtype), axis=1)
    measured = (grid.sides[occupied, None] & masks) != 0
    weights = np.concatenate([np.ones(len(known)), np.full(measured.size, sides)])
    return np.concatenate([known, measured.reshape(-1)]), weights


def side_columns(grid: OccupancyGrid, options: LookaheadOptions) -> np.ndarray:
    """The sides, rows of the grid's sight bins that count as one: each bin, or without `steep_measures` each
    but the steep band's (`OccupancyGrid.side_bins`); with 2 `bands` a sector's down and level bins one row,
    with 1 its down, level and up bins (a row of one bin repeats it)."""
    bins = np.arange(grid.sight_bins) if options.steep_measures else grid.side_bins()
    band = bins % (4 if grid.steep_deg else 3) - bool(grid.steep_deg)  # -1 steep, 0 down, 1 level, 2 up
    width = 4 - options.bands  # the bins of a down row
    return np.array([[b + k for k in range(width)] if kind == 0 else [b] * width
                     for b, kind in zip(bins, band, strict=True) if not 0 < kind < width])


def stereo_partner(view: Viewpoint, baseline: float = STEREO_BASELINE_M, side: str = "back") -> Viewpoint:
    """The view's second frame `baseline` metres (a chord) from it on `side`: back or forward along its
    orbit (its radius and elevation kept), or up its meridian (its radius and azimuth kept)."""
    if side not in PARTNER_SIDES:
        raise ValueError(f"a second frame's side is one of {PARTNER_SIDES}, got {side!r}")
    if side == "up":
        return Viewpoint(view.radius, view.azimuth,
                         view.elevation + 2 * np.arcsin(min(baseline / (2 * view.radius), 1.0)))
    horizontal = max(view.radius * np.cos(view.elevation), baseline)
    turn = 2 * np.arcsin(baseline / (2 * horizontal))
    return Viewpoint(view.radius, view.azimuth + (turn if side == "forward" else -turn), view.elevation)


def lookahead_planner(settings: PlanSettings, seed: int, argument: str | None) -> LookaheadPlanner:
    """The registry's `lookahead`: the validated setting, or `lookahead:W` with flight weight W a metre."""
    if argument is None:
        return LookaheadPlanner()
    return LookaheadPlanner(flight=flight_weight(argument))


def stereo_lookahead_planner(settings: PlanSettings, seed: int, argument: str | None) -> LookaheadPlanner:
    """The registry's `lookahead-stereo`: the look-ahead on stereo depth from two frames a view, on forward
    steps planned as a whole route, valuing sides never measured (a ray over `STEREO_STEEP` down measures
    none), under a battery's hinge: the validated setting, or `lookahead-stereo:W` another flight weight,
    `lookahead-stereo:W,M` (or `:,M`) a battery of M metres before the hinge whatever the views, instead of
    `STEREO_HINGE`'s that grows past 13 views."""
    weight, comma, battery = (argument or "").partition(",")
    flight = flight_weight(weight) if weight else STEREO_FLIGHT
    allowance, per_view = (battery_metres(battery), 0.0) if comma else (STEREO_HINGE[0], STEREO_PER_VIEW)
    return LookaheadPlanner(flight=flight, depth="stereo", blank_images=settings.blank_images,
                            options=LookaheadOptions(forward=STEREO_FORWARD, sides=STEREO_SIDES,
                                                     allowance_m=allowance, excess=STEREO_HINGE[1],
                                                     battery_per_view_m=per_view, steep_deg=STEREO_STEEP,
                                                     steep_measures=False, route=STEREO_ROUTE,
                                                     votes=STEREO_VOTES))


def battery_metres(argument: str) -> float:
    """The metres of flight before the battery's hinge that `lookahead-stereo:W,M` gives (M > 0)."""
    usage = "lookahead-stereo:W,M takes a battery of M > 0 metres before the hinge"
    metres = spec_number(argument, usage)
    if not 0 < metres < float("inf"):
        raise ValueError(f"{usage}, got {argument!r}")
    return metres


def flight_weight(argument: str) -> float:
    """The flight weight a metre that `lookahead:W` gives."""
    return spec_number(argument, "lookahead:W takes a flight weight a metre")


def spec_number(argument: str, usage: str) -> float:
    """A planner spec's number, or a ValueError saying `usage` and what was given."""
    try:
        return float(argument)
    except ValueError:
        raise ValueError(f"{usage}, got {argument!r}") from None
