"""Fan-out figures (`nbv.fanout`): the same units of work in this process, on 1 and 2 local workers, on Ray.

The units are `nbv compare`'s plan runs (random and circle planners x seeds) on
the test building at 160x120, 4 spp, 8 views, scored against the ground-truth
mesh as the reference (no full scan to render). Each executor runs all of them
into its own fresh folder, timed from handing them over to the last one done,
so worker start-up (imports, scene loading, Mitsuba's kernels; for Ray the local
instance too) is counted. A warm-up unit runs in this process first, so the
in-process figure does not pay for the texture cache or the kernel cache. The
speed-up of an executor is the in-process wall time over its own; "1 local
worker" is a single spawned process (the price of leaving this one). Core
seconds per unit (2 workers' wall time x 2 / units) is the cost the capacity
plan scales (docs/capacity.md). Every executor's runs must give the in-process
numbers: the bench checks it. The speed-up needs idle cores: the 1-minute load
average at the start is reported beside it.
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from nbv.bench import BenchResult
from nbv.experiments.compare import CompareConfig, comparison_tasks
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_stages
from nbv.fanout.processes import run_in_processes
from nbv.fanout.task import Task
from nbv.recon.config import MetricsConfig, ReconstructionConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes import load_scene
from scenes.spec import SceneSpec

SCENE = "test_building"
PLANNERS = ("random", "circle")


def comparison(out: Path, reference: Path, seeds: tuple[int, ...]) -> CompareConfig:
    """The benchmarked comparison: `len(PLANNERS) * len(seeds)` plan units."""
    return CompareConfig(scene=SceneSpec(scene=SCENE), planners=PLANNERS, seeds=seeds, views=8,
                         camera=UAVCamera(160, 120), render=RenderSettings(spp=4), reference=reference,
                         metrics=MetricsConfig(n_points=20_000),
                         recon=ReconstructionConfig(voxel_size_m=0.01), out=out)


def _wall(runner: Callable[[list[list[Task]]], object], config: CompareConfig) -> float:
    reference, plans = comparison_tasks(config)
    start = time.perf_counter()
    runner([reference, plans])
    return time.perf_counter() - start


def _numbers(config: CompareConfig) -> list[dict]:
    _, plans = comparison_tasks(config)
    docs = [json.loads(task.result.read_text()) for task in plans]
    return [{k: doc[k] for k in ("viewpoints", "gt", "reference")} for doc in docs]


def run(quick: bool) -> list[BenchResult]:
    """Wall time of the units in process, speed-ups of 1 and 2 local workers and 2 Ray workers."""
    seeds = (0, 1) if quick else (0, 1, 2, 3)
    busy = os.getloadavg()[0]
    executors: dict[str, Callable[[list[list[Task]]], object]] = {
        "in process": lambda stages: run_stages(stages),
        "1 local worker": lambda stages: run_in_processes(stages, 1, lambda task: None),
        "2 local workers": lambda stages: run_stages(stages, ExecutorConfig(workers=2)),
        "2 Ray workers (local instance)": lambda stages: run_stages(stages, ExecutorConfig(2, "auto")),
    }
    with tempfile.TemporaryDirectory() as scratch:
        root = Path(scratch)
        reference = root / "reference.ply"
        load_scene(SCENE).target_mesh().export(reference)
        _wall(executors["in process"], comparison(root / "warm-up", reference, (99,)))
        walls, numbers = {}, {}
        for name, runner in executors.items():
            config = comparison(root / name.replace(" ", "_"), reference, seeds)
            walls[name] = _wall(runner, config)
            numbers[name] = _numbers(config)
    units = len(PLANNERS) * len(seeds)
    label = f"{units} plan units ({SCENE}, 160x120, 4 spp, 8 views)"
    results = [BenchResult("fanout", "1-minute load average at the start (cores busy before the bench)",
                           busy, ""),
               BenchResult("fanout", f"wall time in process, {label}", walls["in process"], "s"),
               BenchResult("fanout", "core seconds per plan unit (2 local workers' wall x 2 / units)",
                           walls["2 local workers"] * 2 / units, "s")]
    for name in list(executors)[1:]:
        same = numbers[name] == numbers["in process"]
        results.append(BenchResult("fanout", f"speed-up, {name}, over in process",
                                   walls["in process"] / walls[name], "x",
                                   f"numbers identical to in process: {'met' if same else 'NOT met'}"))
    return results
