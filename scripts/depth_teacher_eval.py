"""The teacher's look-ahead on what the UAV measures: a depth teacher against the tuned orbit (round 23).

The privileged teacher (`nbv.rl.expert`) scores each of its 125 candidate steps by the true surface samples
that its next views would be the first to see; its students do not follow it (rounds 17 to 23). The
`lookahead` planner (`nbv.planning.lookahead`) runs the same scoring at flight time on an occupancy grid
fused from the depth flown instead of the mesh; this study flies it with several flight weights (coverage
points of the grid's voxels a metre), grid resolutions and ray strides (every n-th pixel at the default
preset's 160 x 120) on the validation buildings, scored as `scripts/looks_eval.py` scores every planner;
round 23 chose `lookahead`'s setting with it. With `--stereo`, each weight is also flown on the depth that
plane-sweep stereo finds between two frames a view (`lookahead-stereo`, name ending _stereo), and again with
every frame blank (round 25); `--partners back up` takes its second frames on those sides and `--agree N`
fuses only depths N pairs agree on, `--votes` weighs the grid's hits against passes (round 26; name ending
_stereo_back-up, _stereo_back-up_a2, _stereo_v). Round 27: `--frontier K` counts only each ray's first K
unknown voxels (name ending _fK), `--allowance M --excess W` charges W a metre more past M metres (_hMxW),
`--patience N` gives up on unknown voxels N views reached without measuring (_pN), `--horizon H` scores H
views ahead (_HH), `--next-to-free` counts only unknown voxels beside free space (_nf); `--distinct` flies
each look-ahead again never stepping onto a view already flown (rounds 24 and 27; name ending _d). Round 28:
`--forward` steps as a pilot's orbit, always forward by 27.7 to 55.4 degrees (_fw). Round 29: `--spacing M`
never steps within M metres of a camera flown (_spM). Round 30: `--sight D`
never steps to a view whose sight line lies within D degrees of one flown's (_siD). Round 31: `--sides W`
values each occupied voxel met from a direction it was never measured from at W unknown voxels (_sdW).
Round 33: `--per-view P` grows the battery to P metres a view where that passes --allowance (_pvP).
Round 35: `--steep D` gives rays looking down more steeply than D degrees sight bins of their own (_stpD);
round 36: `--steep-blind` makes that band measure no side instead (_stpDb); `--ceiling C` holds every step at
or under C degrees of elevation (_ceC). Round 38: `--pace` charges the hinge on each leg's metres past an
even share of the battery (_pc). Round 39: `--route` plans every view still to take together as one
route, re-planned at each view (_rt). Round 40: `--restarts N` also improves N routes of random steps
(_rsN). Round 45: `--sectors 8` measures sides from eight 45-degree horizontal sectors, not quadrants (_sc8).
Round 48: `--bands 2` tells sides by two vertical bands, down and level one (_bd2); round 49: `--bands 1` by
none (_bd1). Round 50: `--padding-free` starts the grid's padding, outside the target's bounds, free (_pf).
Round 51 (a diagnostic): `--stereo-mask` also flies stereo's own flight on the depth camera's exact depth,
kept only at the pixels where stereo measures one (_mask): what stereo's density costs, apart from its errors;
`--in-box` fuses no stereo depth whose point lies outside the target's bounds, grown by a voxel (_ib).

    python scripts/depth_teacher_eval.py --flight-reward 0.05 0.2 --out OUT --work WORK
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from nbv.planning.config import PlanSettings
from nbv.planning.lookahead import (
    BANDS,
    HORIZON,
    PARTNER_SIDES,
    STEREO_PARTNERS,
    LookaheadOptions,
    LookaheadPlanner,
)
from nbv.planning.registry import make_planner
from nbv.planning.world import PlanningWorld
from nbv.recon.occupancy import SECTORS, OccupancyGrid
from nbv.rl.presets import default_preset
from render.viewpoint import Viewpoint

sys.path.insert(0, str(Path(__file__).parent))
import looks_eval  # noqa: E402


class StereoMaskedPlanner(LookaheadPlanner):
    """A diagnostic (round 51): each frame stereo measures fused with the depth camera's exact depth, at the
    pixels where stereo measures a depth alone: stereo's density with exact depth's accuracy."""

    def measured(self, world: PlanningWorld, grid: OccupancyGrid,
                 view: Viewpoint) -> list[tuple[np.ndarray, Viewpoint]]:
        """`LookaheadPlanner.measured`'s stereo depths, each replaced by the exact depth where finite."""
        return [(np.where(np.isfinite(depth), world.source.render_depth(at), np.nan).astype(np.float32), at)
                for depth, at in super().measured(world, grid, view)]


def arguments() -> argparse.Namespace:
    """The command line: the look-ahead's settings, then the study's (`looks_eval.study_arguments`)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flight-reward", type=float, nargs="+", default=[0.05])
    parser.add_argument("--grid-resolution", type=int, default=32, help="voxels along the longest side")
    parser.add_argument("--gain-ray-stride", type=int, default=8, help="every n-th pixel's ray, both axes")
    parser.add_argument("--distinct", action="store_true",
                        help="also fly each weight (camera, stereo) never stepping onto a view already "
                             "flown (name ending _d)")
    stereo_arguments(parser)
    parser.add_argument("--frontier", type=int, default=0,
                        help="a view sees only each ray's first this many unknown voxels (0: all of them)")
    parser.add_argument("--allowance", type=float, default=0.0,
                        help="metres of the flight before --excess a metre more is charged")
    parser.add_argument("--excess", type=float, default=0.0,
                        help="coverage points a metre charged past --allowance (0: no hinge)")
    parser.add_argument("--per-view", type=float, default=0.0,
                        help="the battery grows to this many metres a view where that passes --allowance")
    parser.add_argument("--patience", type=int, default=0,
                        help="an unknown voxel that many views flown reached unmeasured counts as seen")
    parser.add_argument("--horizon", type=int, default=HORIZON, help="views scored ahead of each step")
    parser.add_argument("--next-to-free", action="store_true",
                        help="a view sees only the unknown voxels beside free space it reaches")
    parser.add_argument("--forward", action="store_true",
                        help="every step advances the azimuth the same way, 27.7 to 55.4 degrees")
    parser.add_argument("--spacing", type=float, default=0.0,
                        help="never step within this many metres of a camera flown (0: no rule)")
    parser.add_argument("--sight", type=float, default=0.0,
                        help="never step within this many degrees of a sight line flown (0: no rule)")
    parser.add_argument("--sides", type=float, default=0.0,
                        help="an occupied voxel met from a direction never measured is worth this many "
                             "unknown voxels (0: nothing)")
    parser.add_argument("--steep", type=float, default=0.0,
                        help="with --sides, rays looking down more steeply than this many degrees are a "
                             "direction of their own (0: none)")
    parser.add_argument("--sectors", type=int, default=4, choices=SECTORS,
                        help="with --sides, a side is measured from one of 4 quadrants or 8 sectors")
    parser.add_argument("--padding-free", action="store_true", help="the grid's padding starts free")
    parser.add_argument("--bands", type=int, default=3, choices=BANDS, help="with --sides, vertical bands")
    parser.add_argument("--steep-blind", action="store_true",
                        help="with --steep, the steep band measures no side (neither marks nor gains one)")
    parser.add_argument("--ceiling", type=float, default=0.0,
                        help="every step's elevation at most this many degrees (0: the action space's own)")
    parser.add_argument("--pace", action="store_true",
                        help="the hinge charges each leg past an even share of the battery (round 38)")
    parser.add_argument("--route", action="store_true",
                        help="plan every view still to take together, re-planned at each view (round 39)")
    parser.add_argument("--restarts", type=int, default=0,
                        help="with --route, also improve this many routes of random steps (round 40)")
    looks_eval.study_arguments(parser)
    return parser.parse_args()


def stereo_arguments(parser: argparse.ArgumentParser) -> None:
    """The stereo options: whether to fly it, its second frames, agreement, votes, the masked diagnostic."""
    parser.add_argument("--stereo", action="store_true",
                        help="also fly each weight on stereo depth from the images (name ending _stereo)")
    parser.add_argument("--no-camera", action="store_true",
                        help="with --stereo, fly only the stereo look-ahead (not the depth camera's)")
    parser.add_argument("--partners", nargs="+", choices=PARTNER_SIDES, default=list(STEREO_PARTNERS),
                        help="with --stereo, the sides of each view's second frames")
    parser.add_argument("--agree", type=int, default=0,
                        help="with --stereo, fuse only the depths this many pairs agree on (0: every pair's)")
    parser.add_argument("--votes", action="store_true",
                        help="with --stereo, the grid weighs hits against passes, one vote an image")
    parser.add_argument("--in-box", action="store_true",
                        help="with --stereo, fuse no depth whose point lies outside the target's bounds")
    parser.add_argument("--stereo-mask", action="store_true",
                        help="with --stereo, also fly the depth camera's exact depth kept only where stereo "
                             "measures (name ending _mask; stereo's density, exact depth's accuracy)")


def named(options: LookaheadOptions) -> str:
    """A run's name ending for `options`' variants (rounds 27 to 40), empty for the teacher's own."""
    o = options
    return (f"_f{o.frontier}" if o.frontier else "") \
        + (f"_h{o.allowance_m:g}x{o.excess:g}" if o.excess else "") \
        + (f"_pv{o.battery_per_view_m:g}" if o.battery_per_view_m else "") \
        + (f"_p{o.patience}" if o.patience else "") \
        + (f"_H{o.horizon}" if o.horizon != HORIZON else "") + ("_nf" if o.next_to_free else "") \
        + ("_fw" if o.forward else "") + (f"_sp{o.spacing_m:g}" if o.spacing_m else "") \
        + (f"_si{o.sight_deg:g}" if o.sight_deg else "") + (f"_sd{o.sides:g}" if o.sides else "") \
        + (f"_sc{o.sectors}" if o.sectors != 4 else "") + (f"_bd{o.bands}" if o.bands != 3 else "") \
        + ("_pf" if o.padding_free else "") \
        + (f"_stp{o.steep_deg:g}" + "b" * (not o.steep_measures) if o.steep_deg else "") \
        + (f"_ce{o.ceiling_deg:g}" if o.ceiling_deg else "") + ("_pc" if o.pace else "") \
        + ("_rt" if o.route else "") + (f"_rs{o.restarts}" if o.restarts else "")


def stereo_suffix(paired: LookaheadOptions) -> str:
    """A stereo run's name ending: its second frames' sides where not `lookahead-stereo`'s, agreement,
    votes (round 26), depths within the box (round 51), then `named`'s."""
    return "_stereo" + ("" if paired.partners == STEREO_PARTNERS else "_" + "-".join(paired.partners)) \
        + (f"_a{paired.agree}" if paired.agree else "") + ("_v" if paired.votes else "") \
        + ("_ib" if paired.in_box else "") + named(paired)


def main() -> None:
    args = arguments()
    looks_eval.refuse_held_out(args.scenes)
    trained = default_preset().env
    rays = max(1, trained.camera.width // args.gain_ray_stride)
    planners = {name: (make_planner(name, PlanSettings()), False) for name in ("orbit", "orbit2", "random")}
    names, blanks = [], {}
    options = LookaheadOptions(frontier=args.frontier, allowance_m=args.allowance, excess=args.excess,
                               patience=args.patience, horizon=args.horizon, next_to_free=args.next_to_free,
                               forward=args.forward, spacing_m=args.spacing, sight_deg=args.sight,
                               sides=args.sides, battery_per_view_m=args.per_view, steep_deg=args.steep,
                               sectors=args.sectors, bands=args.bands, padding_free=args.padding_free,
                               steep_measures=not args.steep_blind, ceiling_deg=args.ceiling, pace=args.pace,
                               route=args.route, restarts=args.restarts)
    paired = replace(options, partners=tuple(args.partners), agree=args.agree, votes=args.votes,
                     in_box=args.in_box)
    for w in args.flight_reward:
        name = f"depth-teacher_r{args.grid_resolution}_s{args.gain_ray_stride}_w{w:g}"
        for distinct in (False, True) if args.distinct else (False,):
            if not args.no_camera:
                camera = name + "_d" * distinct + named(options)
                planners[camera] = (LookaheadPlanner(flight=w, grid=args.grid_resolution, rays=rays,
                                                     options=replace(options, distinct=distinct)), False)
                names.append(camera)
            if args.stereo:
                setting = dict(flight=w, grid=args.grid_resolution, rays=rays, depth="stereo",
                               options=replace(paired, distinct=distinct))
                flown = name + stereo_suffix(paired) + "_d" * distinct
                planners[flown] = (LookaheadPlanner(**setting), False)
                blanks[flown] = LookaheadPlanner(blank_images=True, **setting)
                names.append(flown)
                if args.stereo_mask:
                    planners[flown + "_mask"] = (StereoMaskedPlanner(**setting), False)
                    names.append(flown + "_mask")
    results = looks_eval.evaluate(planners, trained, args.scenes, args.seeds, args.views, args.work,
                                  blanks=blanks)
    looks_eval.conclude(args, results, names,
                        f"{args.views} views: the teacher's look-ahead on depth vs the tuned orbit")


if __name__ == "__main__":
    main()
