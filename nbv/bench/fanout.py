"""Fan-out figures (`nbv.fanout`): the same plan units in this process, on 2 local workers, on 2 Ray workers.

The units are a planner study's plan runs (`nbv.experiments.planner_study`,
what `nbv compare` runs) at the size `make tables` runs them: the random and
circle planners x 4 seeds on a preset building, 13 views at 320x240
with the default render, TSDF and metric settings, scored against the
ground-truth mesh given as the reference (so no full scan is rendered inside
the timing). Each executor runs all of them into its own fresh folder, timed
from starting its workers (`start_workers`: spawning them or starting the local
Ray instance, their imports, their first scene build) to the last unit done,
so start-up is counted, once per study as a study pays it. A warm-up unit runs
in this process first, so the in-process figure pays for neither the texture
nor the kernel cache. The speed-up of an executor is the in-process wall time
over its own; core seconds per unit (2 workers' wall time x 2 / units) is the
cost the capacity plan scales (docs/capacity.md). Every executor's runs must
give the in-process numbers (viewpoints and every metric): the bench checks it.
The speed-up needs idle cores: the 1-minute load average before and after is
reported beside it. `--quick` runs 4 tiny units on the test building.
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from nbv.bench import BenchResult
from nbv.experiments.planner_study import PlannerStudy, plan_units, study_stages
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_stages, start_workers
from nbv.planning.config import PlanSettings
from nbv.recon.config import MetricsConfig, ReconstructionConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes import load_scene

PLANNERS = ("random", "circle")
"""The planners of the benchmarked units (cheap to decide: the time goes to rendering, fusing, scoring)."""
EXECUTORS = {"in process": ExecutorConfig(),
             "2 local workers": ExecutorConfig(workers=2),
             "2 Ray workers (local instance)": ExecutorConfig(workers=2, ray="auto")}
"""What each figure runs the units on, in this order."""
SPEED_UP_GOAL = 1.6
"""Issue goal: 2 local workers at least this much faster than in process on an idle 2-core machine."""


@dataclass(frozen=True)
class Size:
    """The benchmarked units' size."""

    scene: str
    seeds: tuple[int, ...]
    views: int
    camera: UAVCamera
    render: RenderSettings
    metrics: MetricsConfig
    recon: ReconstructionConfig

    def label(self) -> str:
        """e.g. '8 plan units (alpine_chalet, 13 views at 320x240, 16 spp)'."""
        return (f"{len(PLANNERS) * len(self.seeds)} plan units ({self.scene}, {self.views} views at "
                f"{self.camera.width}x{self.camera.height}, {self.render.spp} spp)")


FULL = Size("alpine_chalet", (0, 1, 2, 3), 13, UAVCamera(), RenderSettings(), MetricsConfig(),
            ReconstructionConfig())
"""`make tables`' plan units: its camera, render, fusion and metric settings, 13 views (paper Fig. 1)."""
QUICK = Size("test_building", (0, 1), 4, UAVCamera(96, 72), RenderSettings(spp=1),
             MetricsConfig(n_points=5_000), ReconstructionConfig(voxel_size_m=0.01))
"""`nbv bench --quick`: 4 tiny units, to check the bench runs."""


def comparison(size: Size, out: Path, reference: Path, seeds: tuple[int, ...]) -> PlannerStudy:
    """The benchmarked planner study of `seeds` into `out`, scored against `reference`."""
    settings = PlanSettings(camera=size.camera, render=size.render, metrics=size.metrics, recon=size.recon,
                            reference=reference)
    return PlannerStudy(scenes=(size.scene,), planners=PLANNERS, seeds=seeds, budgets=(size.views,),
                        settings=settings, out=out)


def numbers(study: PlannerStudy) -> list[dict]:
    """Every unit's viewpoints and metrics, read back from its plan.json."""
    docs = [json.loads(task.result.read_text()) for task in plan_units(study)]
    return [{k: doc[k] for k in ("viewpoints", "gt", "reference")} for doc in docs]


def timed(executor: ExecutorConfig, study: PlannerStudy) -> float:
    """Wall seconds from starting `executor`'s workers to the last of `study`'s units done."""
    start = time.perf_counter()
    start_workers(executor)
    run_stages(study_stages(study), executor)
    return time.perf_counter() - start


def run(quick: bool) -> list[BenchResult]:
    """Wall time of the units in process, and the speed-ups of 2 local and 2 Ray workers over it."""
    size = QUICK if quick else FULL
    busy = os.getloadavg()[0]
    walls, found = {}, {}
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        reference = root / "reference.ply"
        load_scene(size.scene).target_mesh().export(reference)
        run_stages(study_stages(comparison(size, root / "warm-up", reference, (99,))))
        for name, executor in EXECUTORS.items():
            config = comparison(size, root / name.replace(" ", "_"), reference, size.seeds)
            walls[name] = timed(executor, config)
            found[name] = numbers(config)
    units = len(PLANNERS) * len(size.seeds)
    results = [BenchResult("fanout", "1-minute load average at the start (cores busy before the bench)",
                           busy, ""),
               BenchResult("fanout", "1-minute load average at the end", os.getloadavg()[0], ""),
               BenchResult("fanout", f"wall time in process, {size.label()}", walls["in process"], "s"),
               BenchResult("fanout", "core seconds per plan unit (2 local workers' wall x 2 / units)",
                           walls["2 local workers"] * 2 / units, "s")]
    for name in list(EXECUTORS)[1:]:
        same = "met" if found[name] == found["in process"] else "NOT met"
        speed_up = walls["in process"] / walls[name]
        goal = f"numbers identical to in process: {same}"
        if name == "2 local workers":
            goal += f"; >= {SPEED_UP_GOAL:g} on an idle 2-core machine " \
                    f"({'met' if speed_up >= SPEED_UP_GOAL else 'NOT met'})"
        results.append(BenchResult("fanout", f"speed-up, {name}, over in process", speed_up, "x", goal))
    return results
