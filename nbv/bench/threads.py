"""The thread policy under load (common/threads.py): SIFT and a planning step, idle and beside a busy process.

Side by side in one run, on the same rendered views of the default scene: Kornia
SIFT with the policy's torch threads (1) and with one per core (torch's
default), OpenCV SIFT, and their ratio; then the planning step a deployed
policy adds per view once the image is in hand (no render): features with the
config's default backend, the Bag of Views reward, the actor's forward pass
(freshly initialised: the same cost as a trained one), at 160x120. Each is
timed on an idle machine and again beside one competing busy process (a Python
`while True: pass`), which is always terminated. "Idle" means no process of
ours besides this one: the 1-minute load average at the start is reported,
since other jobs on the machine load it too. Views are extracted one at a time,
as the env does.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import torch
from tensordict import TensorDict
from torchrl.envs.utils import ExplorationType, set_exploration_type

from common.threads import limit_torch_threads, worker_threads
from nbv.bench import BenchResult
from nbv.bench.bov import render_views
from nbv.bov.bag import BagOfViews
from nbv.features.sift import FeatureConfig, extract_features
from nbv.features.source import gray_frame
from nbv.rl.agent import make_actor
from nbv.rl.bov_observation import BOV_KEY, bov_observation_size, bov_vector, novelty_of
from nbv.rl.config import EnvConfig
from nbv.rl.look_map import LOOK_MAP_SIZE, look_of
from render.camera import UAVCamera
from render.viewpoint import Viewpoint
from scenes import DEFAULT_SCENE
from scenes.spec import SceneSet

GOAL_PLANNING_MS = 50.0
"""Issue goal: a planning step (no render) in <= 50 ms on 2 cores ..."""
GOAL_BUSY_RATIO = 2.0
"""... and within 2x of that goal (<= 100 ms) beside a competing busy process."""
LOADS = ("idle", "busy")


@contextmanager
def busy_process() -> Iterator[subprocess.Popen]:
    """One competing process spinning on a core for the block; terminated (killed if need be) on exit."""
    proc = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.2)  # let it start spinning
        yield proc
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@contextmanager
def load(kind: str) -> Iterator[None]:
    """Nothing for "idle", a `busy_process` for "busy"."""
    if kind == "busy":
        with busy_process():
            yield
    else:
        yield


def per_view_ms(images: np.ndarray, config: FeatureConfig, threads: int, repeats: int) -> float:
    """Best over `repeats` passes (after one warm-up) of the mean ms per view, one view per call."""
    with limit_torch_threads(threads):
        best = math.inf
        for i in range(repeats + 1):
            start = time.perf_counter()
            for image in images:
                extract_features([image], config)
            if i:
                best = min(best, time.perf_counter() - start)
    return 1000.0 * best / len(images)


def bench_sift(images: np.ndarray, label: str, repeats: int) -> list[BenchResult]:
    """Kornia SIFT on the policy's threads and on all cores, and OpenCV SIFT, idle and busy, with ratios."""
    policy, cores = worker_threads(), len(os.sched_getaffinity(0))
    kornia, opencv = FeatureConfig(), FeatureConfig(backend="opencv")
    results = []
    for kind in LOADS:
        with load(kind):
            k1 = per_view_ms(images, kornia, policy, repeats)
            o = per_view_ms(images, opencv, policy, repeats)
            # one pass over two views: on loaded cores this takes seconds per view
            kn = per_view_ms(images[:2], kornia, cores, 1) if cores != policy else k1
        rows = [(f"SIFT Kornia {label}, {policy} torch thread (policy), {kind}", k1, "ms/view"),
                (f"SIFT Kornia {label}, {cores} torch threads (all cores), {kind}", kn, "ms/view"),
                (f"SIFT OpenCV {label}, {kind}", o, "ms/view"),
                (f"SIFT Kornia ({policy} thread) / OpenCV {label}, {kind}", k1 / o, "x"),
                (f"SIFT Kornia {cores} threads / {policy} thread {label}, {kind}", kn / k1, "x")]
        results += [BenchResult("threads", *row) for row in rows]
    return results


def planning_step_ms(images: np.ndarray, config: EnvConfig, repeats: int) -> dict[str, float]:
    """Mean ms per view of features, BoV reward and actor forward, from the best of `repeats` passes.

    Each pass steps through every view in turn (azimuth 0.7 rad apart) with a fresh Bag of Views, which
    fills up as in an episode; one untimed pass first warms up the actor, the extractor and the BoV. With
    `config.bov_observation` the Bag of Views stage also builds the state's `bov` vector, which the actor
    reads.
    """
    actor = make_actor(config.history, config.obs_size, extra=bov_observation_size(config))
    features = config.bov.feature_config()
    tau, side = config.history, config.obs_size
    td = TensorDict({"pixels": torch.zeros(tau, side, side, dtype=torch.uint8),
                     "viewpoints": torch.zeros(tau, 3)}, [])
    best = {"total": math.inf}
    with torch.no_grad(), set_exploration_type(ExplorationType.DETERMINISTIC):
        for p in range(repeats + 1):
            bov = BagOfViews.from_config(config.bov, seed=p)
            looked = np.zeros(LOOK_MAP_SIZE, np.float32)
            stages = {"features": 0.0, "bov": 0.0, "policy": 0.0}
            for i, rgb in enumerate(images):
                t0 = time.perf_counter()
                descriptors = extract_features([rgb], features)[0].descriptors
                t1 = time.perf_counter()
                reward = bov.reward(descriptors, 0.7 * i)
                if config.bov_observation:
                    if config.look_map:
                        looked = np.maximum(looked, look_of(Viewpoint(2.0, 0.7 * i, 0.3)))
                    vector = bov_vector(bov, novelty_of(reward, bov), i + 1, 0.5 * i, config, looked)
                    td[BOV_KEY] = torch.from_numpy(vector)
                t2 = time.perf_counter()
                td["pixels"] = torch.cat([td["pixels"][1:], torch.from_numpy(gray_frame(rgb, side))[None]])
                actor(td)
                t3 = time.perf_counter()
                stages["features"] += t1 - t0
                stages["bov"] += t2 - t1
                stages["policy"] += t3 - t2
            stages["total"] = sum(stages.values())
            if p and stages["total"] < best["total"]:
                best = stages
    return {k: 1000.0 * v / len(images) for k, v in best.items()}


def bench_planning(images: np.ndarray, repeats: int) -> list[BenchResult]:
    """The planning step (and its stages) at the policy's threads, idle and busy, beside the goals."""
    camera = UAVCamera(images.shape[2], images.shape[1])
    config = EnvConfig(scenes=SceneSet(scene=(DEFAULT_SCENE,)), camera=camera)
    label = (f"planning step {images.shape[2]}x{images.shape[1]} ({config.bov.sift.backend} SIFT + BoV "
             f"reward + policy, no render, {worker_threads()} torch thread)")
    ms, results = {}, []
    with limit_torch_threads(worker_threads()):
        for kind in LOADS:
            with load(kind):
                ms[kind] = planning_step_ms(images, config, repeats)
            for stage in ("features", "bov", "policy"):
                name = f"planning step {stage}, {kind}"
                results.append(BenchResult("threads", name, ms[kind][stage], "ms"))
    idle, busy = ms["idle"]["total"], ms["busy"]["total"]
    busy_goal, ratio = GOAL_BUSY_RATIO * GOAL_PLANNING_MS, busy / idle
    return results + [
        BenchResult("threads", f"{label}, idle", idle, "ms",
                    f"<= {GOAL_PLANNING_MS:g}: {'met' if idle <= GOAL_PLANNING_MS else 'NOT met'}"),
        BenchResult("threads", f"{label}, busy", busy, "ms",
                    f"<= {busy_goal:g}: {'met' if busy <= busy_goal else 'NOT met'}"),
        BenchResult("threads", "planning step busy / idle", ratio, "x"),
    ]


def run(quick: bool) -> list[BenchResult]:
    """SIFT at 160x120 (and 320x240 unless quick) and the 160x120 planning step, idle and busy."""
    resolutions = ((160, 120),) if quick else ((160, 120), (320, 240))
    count, repeats = (2, 1) if quick else (6, 2)
    results = [BenchResult("threads", "1-minute load average at the start (cores busy before the bench)",
                           os.getloadavg()[0], "")]
    small = None
    for width, height in resolutions:
        images = render_views(width, height, count)[0]
        small = images if small is None else small
        results += bench_sift(images, f"{width}x{height}", repeats)
    results += bench_planning(small, repeats)
    return results
