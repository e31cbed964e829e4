"""The teacher's look-ahead on what the UAV measures: a depth teacher against the tuned orbit (round 23).

The privileged teacher (`nbv.rl.expert`) scores each of its 125 candidate steps by the true surface samples
that its next views would be the first to see; its students do not follow it (rounds 17 to 23). This
planner runs the same look-ahead at flight time on what a depth camera measures instead of the mesh: an
occupancy grid over the target's bounds (`nbv.recon.occupancy`, the infogain planner's), fused from the
depth of every view flown. The teacher's scoring itself (`expert_scores`) is reused: a voxel counts as seen
once it is known (free or occupied), a view "sees" the unknown voxels its rays reach before an occupied one
(`OccupancyGrid.reached`), so a candidate scores 100 x the share of the grid's voxels its look-ahead views
are the first to reach, discounted per step ahead, less the flight-cost weight times each leg's metres
along the viewing shell. It reads depth, a named option of issue 26 reported apart from the policies that
read images alone. Validation buildings only; scored as `scripts/looks_eval.py` scores every planner.

    python scripts/depth_teacher_eval.py --flight-reward 0.05 0.2 --out OUT --work WORK
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from common.io import atomic_folder
from nbv.flight.path import shell_path
from nbv.planning.base import Planner
from nbv.planning.config import PlanSettings
from nbv.planning.infogain import target_grid
from nbv.planning.registry import make_planner
from nbv.recon.config import OccupancyConfig
from nbv.recon.occupancy import UNKNOWN
from nbv.rl.config import EnvConfig
from nbv.rl.env import action_to_viewpoint
from nbv.rl.expert import best_action, expert_scores
from nbv.rl.presets import default_preset
from render.viewpoint import Viewpoint, viewpoint_to_c2w

sys.path.insert(0, str(Path(__file__).parent))
import looks_eval  # noqa: E402


class DepthTeacherPlanner(Planner):
    """The teacher's look-ahead on an occupancy grid fused from the depth flown (module docstring)."""

    name = "depth-teacher"

    def __init__(self, trained: EnvConfig, grid: OccupancyConfig, flight: float, horizon: int = 3,
                 discount: float = 0.9) -> None:
        self.trained, self.grid, self.flight = trained, grid, flight
        self.horizon, self.discount = horizon, discount

    def plan(self, world, views: int | None) -> list[Viewpoint]:
        """The start view, then each next one the best candidate step by the look-ahead on the grid."""
        camera, grid = world.camera, target_grid(world.target, self.grid)
        center = world.target.center()
        stride = self.grid.gain_ray_stride

        def sees(view: Viewpoint) -> np.ndarray:
            return grid.reached(camera.K, viewpoint_to_c2w(view, center), camera.width, camera.height, stride)

        def step(action: np.ndarray, view: Viewpoint) -> Viewpoint:
            return action_to_viewpoint(action, view, self.trained)

        view, chosen = world.start, [world.start]
        for left in range((views or 13) - 1, 0, -1):
            grid.integrate(world.source.render_depth(view), camera.K, viewpoint_to_c2w(view, center),
                           self.grid.integrate_ray_stride)
            known = grid.state.reshape(-1) != UNKNOWN
            scores = expert_scores(view, known, sees, step, self.flight, left, self.horizon, self.discount,
                                   flown_m=shell_path(chosen[0], chosen[1:]).total_m)
            view = step(best_action(scores), view)
            chosen.append(view)
        return chosen


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flight-reward", type=float, nargs="+", default=[0.05])
    parser.add_argument("--teacher-horizon", type=int, default=3)
    parser.add_argument("--teacher-discount", type=float, default=0.9)
    parser.add_argument("--grid-resolution", type=int, default=32, help="voxels along the longest side")
    parser.add_argument("--gain-ray-stride", type=int, default=8, help="every n-th pixel's ray, both axes")
    looks_eval.study_arguments(parser)
    args = parser.parse_args()
    looks_eval.refuse_held_out(args.scenes)
    trained = default_preset().env
    grid = OccupancyConfig(grid_resolution=args.grid_resolution, gain_ray_stride=args.gain_ray_stride)
    planners = {name: (make_planner(name, PlanSettings()), False) for name in ("orbit", "orbit2", "random")}
    names = []
    for w in args.flight_reward:
        name = f"depth-teacher_r{args.grid_resolution}_s{args.gain_ray_stride}_w{w:g}"
        planners[name] = (DepthTeacherPlanner(trained, grid, w, args.teacher_horizon, args.teacher_discount),
                          False)
        names.append(name)
    results = looks_eval.evaluate(planners, trained, args.scenes, args.seeds, args.views, args.work)
    checks = looks_eval.policy_acceptance(results, args.scenes, names)
    table = looks_eval.report(results, args.scenes, args.seeds, args.views, "orbit", checks)
    with atomic_folder(args.out, overwrite=True, outputs=looks_eval.STUDY_OUTPUTS) as out:
        looks_eval.write_study(out, args, results, checks, table,
                               f"{args.views} views: the teacher's look-ahead on depth vs the tuned orbit")
    print(table)


if __name__ == "__main__":
    main()
