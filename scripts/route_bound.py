"""What `lookahead-stereo`'s route reaches knowing the true surface: its search, steps and battery (round 42).

`lookahead-stereo` plans every view still to take as one route (`nbv.planning.route`) on an occupancy grid
fused from stereo depth. This diagnostic runs the same search (`RouteSearch.best`), the same forward steps,
flight weight and battery hinge (`STEREO_FLIGHT`, `STEREO_HINGE`) on the true surface instead: an item is a
sample of the target's surface (`nbv.recon.visibility`, drawn with a seed apart from the score's), a view
reaches the samples it sees, and every sample a view flown sees is known. No image is rendered. It separates
two losses: the gap from `lookahead-stereo` to this bound is what planning on stereo depth costs; the gap
from this bound to the two rings (or to random views' bar) is what the route's forward steps and its battery
leave, whatever the planner knows. `--battery M ...` flies it with M metres before the hinge (13 is
`lookahead-stereo`'s at 13 views). Validation buildings only.

    python scripts/route_bound.py --battery 13 15 17 --seeds 0 1 2 3 4 5 6 7 8 --out OUT --work WORK
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from nbv.flight.path import shell_path
from nbv.planning.base import Planner
from nbv.planning.config import PlanSettings
from nbv.planning.lookahead import FORWARD_STEP, STEREO_FLIGHT, STEREO_HINGE
from nbv.planning.registry import make_planner
from nbv.planning.route import RouteSearch, view_key
from nbv.planning.world import PlanningWorld
from nbv.recon.visibility import scene_visibility
from nbv.rl.env import action_to_viewpoint
from nbv.rl.presets import default_preset
from render.viewpoint import Viewpoint, viewpoint_to_c2w

sys.path.insert(0, str(Path(__file__).parent))
import looks_eval  # noqa: E402

SAMPLE_SEED = 1000
"""Added to a flight's seed for the bound's own surface samples, so that it does not plan on the score's."""


class RouteBound(Planner):
    """`lookahead-stereo`'s route search on the true surface's samples (module docstring)."""

    name = "route-bound"

    def __init__(self, battery_m: float = STEREO_HINGE[0]) -> None:
        """`battery_m`: metres of flight before the hinge's `STEREO_HINGE[1]` points a metre."""
        if not 0 < battery_m < float("inf"):
            raise ValueError(f"the route bound's battery is a finite number of metres > 0, got {battery_m}")
        self.battery_m = battery_m

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """The start view, then each view the first of the best route on the samples left unseen."""
        target = world.target
        truth = scene_visibility(target, world.camera, seed=world.seed + SAMPLE_SEED)
        center, steps = target.center(), replace(world.env, action_mode="forward", relative_step=FORWARD_STEP)
        seen: dict[tuple[float, float, float], np.ndarray] = {}

        def sees(view: Viewpoint) -> np.ndarray:
            key = view_key(view)
            if key not in seen:
                seen[key] = truth.seen(viewpoint_to_c2w(view, center))
            return seen[key]

        def step(action: np.ndarray, here: Viewpoint) -> Viewpoint:
            return action_to_viewpoint(action, here, steps)

        view, chosen, route = world.start, [world.start], None
        known = sees(view).copy()
        for left in range((views or 13) - 1, 0, -1):
            search = RouteSearch(view, left, sees, known, None, step, STEREO_FLIGHT, len(known),
                                 flown_m=shell_path(chosen[0], chosen[1:]).total_m,
                                 allowance_m=self.battery_m, excess=STEREO_HINGE[1])
            route = search.best(route[1:] if route else None)
            view = search.next(route[0], view)
            chosen.append(view)
            known |= sees(view)
        return chosen


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--battery", type=float, nargs="+", default=[STEREO_HINGE[0]],
                        help="metres of flight before the hinge, one bound flown for each")
    looks_eval.study_arguments(parser)
    args = parser.parse_args()
    looks_eval.refuse_held_out(args.scenes)
    trained = default_preset().env
    planners = {name: (make_planner(name, PlanSettings()), False) for name in ("orbit", "orbit2", "random")}
    names = [f"route-bound_b{m:g}" for m in args.battery]
    planners |= {name: (RouteBound(m), False) for name, m in zip(names, args.battery, strict=True)}
    results = looks_eval.evaluate(planners, trained, args.scenes, args.seeds, args.views, args.work,
                                  blank_images=False)
    looks_eval.conclude(args, results, names,
                        f"{args.views} views: lookahead-stereo's route on the true surface")


if __name__ == "__main__":
    main()
