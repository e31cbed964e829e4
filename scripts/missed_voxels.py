"""Where the surface a flight misses sits in the look-ahead's grid (round 43's diagnostic).

Reads two planners' flights on one validation building as `missed_surface.py` does (a `looks_eval` work
folder or studies' results), fuses the depth camera's exact depth of the planner's views into the grid
`lookahead-stereo` plans on (`LOOKAHEAD_GRID` voxels a side, `STEREO_STEEP`'s band), and for the samples of
the true surface that the baseline's views see and the planner's miss, counts the state of the voxel that
holds each: unknown, free (carved by a ray that passed) or occupied, and of the occupied ones how many were
measured from the quadrant the sample faces (`sight_bin` of the reversed normal, not looking steeply down: the
look-ahead counts that side as seen).

    python scripts/missed_voxels.py --work WORK --scene family:39 \
        --planner depth-teacher_r48_s4_w0.1_h13x2_fw_sd1_stp60b_rt --baseline orbit2 --seeds 5 7 --out OUT
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import git_commit
from nbv.features.source import ViewSource
from nbv.planning.infogain import target_grid
from nbv.planning.lookahead import LOOKAHEAD_GRID, STEREO_STEEP
from nbv.planning.world import PlanningWorld
from nbv.recon.config import OccupancyConfig
from nbv.recon.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, sight_bin
from nbv.recon.visibility import scene_visibility
from nbv.rl.config import EnvConfig
from nbv.rl.presets import default_preset
from nbv.rl.validate import evaluation_env_config
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.spec import SceneSet

sys.path.insert(0, str(Path(__file__).parent))
from missed_surface import command_record, flight_arguments, read_flights  # noqa: E402

STATES = {"unknown": UNKNOWN, "free": FREE, "occupied": OCCUPIED}
"""The voxel states counted, by name."""


def voxel_states(grid: OccupancyGrid, samples: np.ndarray, normals: np.ndarray) -> dict[str, int]:
    """How many `samples` (N, 3) lie in voxels of each state, and how many of the occupied ones have been
    measured from the horizontal quadrant their face looks out to (`sight_bin` of -normal; any band but the
    steep one, which `lookahead-stereo` counts as no side)."""
    voxels = grid.voxel_index(samples)
    state = grid.state.reshape(-1)[voxels]
    counts = {name: int(np.sum(state == s)) for name, s in STATES.items()}
    occupied = state == OCCUPIED
    toward = -normals[occupied] / np.linalg.norm(normals[occupied], axis=1, keepdims=True)
    per_quadrant = grid.sight_bins // grid.sectors
    quadrant = sight_bin(toward, grid.steep_deg, grid.sectors) // per_quadrant
    columns = grid.side_bins()  # the look-ahead's sides: the steep band measures none
    measured = ((grid.sides[voxels[occupied], None].astype(np.int64) >> columns) & 1).astype(bool)
    facing = columns // per_quadrant == quadrant[:, None]
    return counts | {"occupied, its quadrant measured": int(np.sum((measured & facing).any(axis=1)))}


def start_row(config: EnvConfig, source: ViewSource, flights: dict[str, dict], seed: int) -> dict:
    """One start view: the planner's views fused on exact depth (rendered by `source`, one for every start
    on the building), the missed samples' voxel states."""
    world = PlanningWorld(config, seed=seed, source=source)
    target, camera = world.target, world.camera
    center, occupancy = target.center(), OccupancyConfig(grid_resolution=LOOKAHEAD_GRID)
    grid = target_grid(target, occupancy, STEREO_STEEP)
    views = {role: [Viewpoint(*v) for v in runs[str(seed)]["viewpoints"]] for role, runs in flights.items()}
    for view in views["planner"]:
        grid.integrate(source.render_depth(view), camera.K, viewpoint_to_c2w(view, center),
                       occupancy.integrate_ray_stride)
    truth = scene_visibility(target, camera, seed=seed)
    seen = {role: truth.seen_by([viewpoint_to_c2w(v, center) for v in flown])
            for role, flown in views.items()}
    missed = seen["baseline"] & ~seen["planner"]
    normals = target.target_mesh().face_normals[truth.faces[missed]]
    return {"seed": seed, "missed": int(missed.sum()), **voxel_states(grid, truth.samples[missed], normals)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    flight_arguments(parser, "orbit2")
    args = parser.parse_args()
    flights = read_flights(args)
    config = evaluation_env_config(default_preset().env, SceneSet(scene=(args.scene,)))
    source = ViewSource(config.camera, config.render, config.bov.feature_config(), config.obs_size)
    rows = [start_row(config, source, flights, seed) for seed in args.seeds]
    head = ["start", "missed", *STATES, "occupied, its quadrant measured"]
    text = markdown_table(head, [[r[k] for k in ("seed", "missed", *head[2:])] for r in rows])
    with atomic_folder(args.out, overwrite=True, outputs=("results.json", "results.md")) as out:
        record = {"command": command_record(args), "commit": git_commit(), "rows": rows}
        write_json(out / "results.json", record)
        write_text(out / "results.md", f"# Where {args.planner} keeps what it misses of {args.baseline}'s "
                   f"surface on {args.scene}\n\nSamples of the true surface (of 20000) the baseline sees and "
                   f"the planner misses, by the state of their voxel in the planner's grid fused from exact "
                   f"depth.\n\n{text}\n")
    print(text)


if __name__ == "__main__":
    main()
