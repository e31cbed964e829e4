"""Look-ahead planners: seconds a view to choose the next one, side by side (`lookahead`, `lookahead-stereo`).

Each planner flies the same views on the built-in scene with the default preset's camera and render
settings (160 x 120, exact renders), one torch thread. A view's time is what the UAV would wait before
flying on: measuring (the depth camera's image, or the second frames' renders and their plane sweeps) and
scoring the 125 candidate steps on the grid. Stereo with three second frames (back, forward, up; round 26)
is measured beside one (round 25), so the price of each added frame is a ratio from the same run; both step
forward (round 28). `lookahead-stereo` itself (one frame, forward, valuing sides never measured under a
battery's hinge, round 31; the rest of the flight planned as one route, round 39) is timed beside round 28's
setting, so the price of those terms is a ratio too.
"""

from __future__ import annotations

import time

from common.threads import set_torch_threads
from nbv.bench import BenchResult
from nbv.planning.config import PlanSettings
from nbv.planning.lookahead import (
    STEREO_FORWARD,
    LookaheadOptions,
    LookaheadPlanner,
    stereo_lookahead_planner,
)
from nbv.planning.world import PlanningWorld
from nbv.rl.presets import default_preset
from nbv.rl.validate import evaluation_env_config
from scenes import DEFAULT_SCENE
from scenes.spec import SceneSet

PLANNERS = {
    "depth camera": LookaheadPlanner(),
    "stereo, one second frame (back; round 28's setting)": LookaheadPlanner(
        depth="stereo", options=LookaheadOptions(forward=STEREO_FORWARD)),
    "lookahead-stereo (one frame, sides never measured, hinge, route; round 39)": stereo_lookahead_planner(
        PlanSettings(), 0, None),
    "stereo, three second frames (back, forward, up)": LookaheadPlanner(
        depth="stereo", options=LookaheadOptions(partners=("back", "forward", "up"), forward=STEREO_FORWARD)),
}
"""The look-aheads timed, by label."""


def seconds_a_view(planner: LookaheadPlanner, views: int) -> float:
    """Wall seconds a view of one `views`-view plan on the built-in scene (its first view excluded: the
    start is given)."""
    env = evaluation_env_config(default_preset().env, SceneSet(scene=(DEFAULT_SCENE,)))
    world = PlanningWorld(env, seed=0)
    world.target  # noqa: B018 (load the scene before the clock starts)
    start = time.perf_counter()
    planner.plan(world, views)
    return (time.perf_counter() - start) / (views - 1)


def run(quick: bool) -> list[BenchResult]:
    """Seconds a view of each look-ahead, and the stereo ones' ratios to the depth camera's and each other
    (the sides and route terms' price: `lookahead-stereo` over round 28's setting)."""
    set_torch_threads(1)
    views = 3 if quick else 9
    seconds = {label: seconds_a_view(planner, views) for label, planner in PLANNERS.items()}
    results = [BenchResult("lookahead", f"{label}: s/view to choose the next, 160x120", value, "s")
               for label, value in seconds.items()]
    camera, one, sides, three = seconds.values()
    results.append(BenchResult("lookahead", "stereo (one frame) / depth camera", one / camera, "x"))
    results.append(BenchResult("lookahead", "stereo three frames / one frame", three / one, "x"))
    results.append(BenchResult("lookahead", "lookahead-stereo (sides, route) / round 28's setting",
                               sides / one, "x"))
    return results
