"""The view lattice: snapping against hand-worked nodes, the cache against direct renders, the env on it."""

from __future__ import annotations

import errno
import math
import os
import signal
from pathlib import Path

import numpy as np
import pytest
import torch
from lock_holder import hold
from tensordict import TensorDict

from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
from nbv.features.sift import extract_features
from nbv.features.source import gray_frame
from nbv.rl.config import EnvConfig, LatticeConfig
from nbv.rl.env import NBVEnv
from nbv.rl.lattice import ViewLattice, build_lattice, lattice_axes, lattice_path
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.variant import select_variant
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.spec import SceneSet

ENOSPC = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
GRID = LatticeConfig(enabled=True, lattice_radii=3, lattice_azimuths=36, lattice_elevations=6)


def config(grid: LatticeConfig = GRID, **kwargs) -> EnvConfig:
    return EnvConfig(scenes=SceneSet(scene=("test_building",)), lattice=grid, **kwargs)


def empty_lattice(cfg: EnvConfig) -> ViewLattice:
    axes = lattice_axes(cfg)
    n = math.prod(len(a) for a in axes)
    return ViewLattice(np.zeros((n, 2, 2), np.uint8), np.zeros(n, int), torch.zeros(0, 128), axes)


def test_axes_and_snapping_error_by_hand():
    cfg = config()
    radii, azimuths, elevations = lattice_axes(cfg)
    assert radii.tolist() == [1.5, 2.0, 2.5]
    assert np.degrees(azimuths[:3]).round(9).tolist() == [0.0, 10.0, 20.0]
    assert np.degrees(elevations).round(9).tolist() == [5.0, 20.0, 35.0, 50.0, 65.0, 80.0]
    assert cfg.snapping_error == pytest.approx((0.25, 5.0, 7.5))


def test_snap_wraps_the_azimuth_and_picks_the_nearest_node():
    lattice = empty_lattice(config())
    node, index = lattice.snap(Viewpoint(2.2, math.radians(356.0), math.radians(27.0)))
    assert (node.radius, node.azimuth, round(math.degrees(node.elevation), 9)) == (2.0, 0.0, 20.0)
    assert index == np.ravel_multi_index((1, 0, 1), (3, 36, 6))


def test_every_viewpoint_lies_within_the_snapping_error_of_its_node():
    cfg = config()
    lattice = empty_lattice(cfg)
    rng = np.random.default_rng(0)
    dr, daz, del_ = cfg.snapping_error
    for r, az, el in cfg.low + rng.random((500, 3)) * (cfg.high - cfg.low):
        node, _ = lattice.snap(Viewpoint(r, az, el))
        assert abs(node.radius - r) <= dr + 1e-12
        assert abs(math.degrees(math.remainder(node.azimuth - az, 2 * math.pi))) <= daz + 1e-9
        assert abs(math.degrees(node.elevation - el)) <= del_ + 1e-9


def test_env_on_a_lattice_sees_cached_node_renders_and_reuses_the_cache(monkeypatch):
    grid = LatticeConfig(enabled=True, lattice_radii=2, lattice_azimuths=4, lattice_elevations=2)
    cfg = config(grid, camera=UAVCamera(64, 48), render=RenderSettings(spp=1), obs_size=16,
                 bov=BoVConfig(ranges=4, words=5, sift=FeatureConfig(backend="opencv")), action_mode="orbit")
    env = NBVEnv(cfg, seed=3)
    td = env.reset()
    start = env.viewpoint
    # The env shows the frame of the start's nearest node, which equals a direct render of that node with
    # the node's seed (its index).
    lattice = env._lattice(env._scene)
    node, index = lattice.snap(start)
    assert np.array_equal(td["pixels"][-1].numpy(), lattice.frames[index])
    renderer = env.source.renderer(env._scene)
    rgb = renderer.render_rgb(viewpoint_to_c2w(node, renderer.center), seed=index)
    frame, descriptors = lattice.observe(index)
    assert np.array_equal(frame, gray_frame(rgb, 16))
    direct = extract_features([rgb], cfg.bov.feature_config())[0].descriptors
    assert torch.allclose(descriptors, direct.half().float())
    # A second env reads the cache: it never renders, yet steps with rewards.
    monkeypatch.setattr("render.renderer.MitsubaRenderer.render_rgb",
                        lambda *a, **k: pytest.fail("a lattice env rendered"))
    again = NBVEnv(cfg, seed=3)
    td = again.rollout(3)
    assert td["next", "reward"].shape == (3, 1)


def test_relative_steps_on_a_lattice_accumulate_from_the_exact_viewpoint(tmp_path, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    grid = LatticeConfig(enabled=True, lattice_radii=3, lattice_azimuths=4, lattice_elevations=2)
    cfg = config(grid, camera=UAVCamera(64, 48), render=RenderSettings(spp=1), obs_size=16,
                 bov=BoVConfig(ranges=4, words=5, sift=FeatureConfig(backend="opencv")),
                 action_mode="relative", relative_step=0.125)
    env = NBVEnv(cfg, seed=1)
    env.reset()
    start = env.viewpoint
    lattice = env._lattice(env._scene)
    for _ in range(3):  # +0.04 m and +0.05 * 75 degrees a step: each far below half a node spacing
        td = env.step(TensorDict({"action": torch.tensor([0.32, 0.0, 0.4])}, []))
    radius = min(start.radius + 3 * 0.32 * 0.125 * 1.0, 2.5)
    elevation = min(start.elevation + 3 * 0.4 * 0.125 * math.radians(75.0), math.radians(80.0))
    assert env.viewpoint.radius == pytest.approx(radius)
    assert env.viewpoint.elevation == pytest.approx(elevation)
    assert env.viewpoint.azimuth == pytest.approx(start.azimuth)
    assert td["next", "viewpoints"][-1, 0].item() == pytest.approx(2 * (radius - 1.5) - 1, abs=1e-6)
    assert np.array_equal(td["next", "pixels"][-1].numpy(), lattice.frames[lattice.snap(env.viewpoint)[1]])


def test_planning_env_renders_exact_viewpoints(tmp_path):
    from nbv.planning.plan import planning_env_config
    from nbv.planning.policy import PolicyPlanner

    class Trained(PolicyPlanner):
        def __init__(self) -> None:
            self.env_config = config()

    from nbv.planning.config import PlanConfig
    from scenes.spec import SceneSpec

    plan = PlanConfig(scene=SceneSpec(scene="test_building"), planner="policy:x", out=tmp_path)
    env_config = planning_env_config(plan, Trained())
    assert env_config.lattice.enabled is False


def test_lattice_units_on_local_workers_cache_what_the_env_renders(tmp_path, monkeypatch):
    from nbv.fanout import ExecutorConfig, run_tasks
    from nbv.rl.lattice import lattice_tasks

    grid = LatticeConfig(enabled=True, lattice_radii=1, lattice_azimuths=4, lattice_elevations=2)
    cfg = config(grid, camera=UAVCamera(64, 48), render=RenderSettings(spp=1), obs_size=32,
                 bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")))
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path / "here"))
    env = NBVEnv(cfg, seed=3)
    env.reset()  # renders the lattice in this process, into this cache
    [here] = lattice_tasks(cfg)
    assert here.done()
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path / "workers"))  # spawned workers inherit it
    [unit] = lattice_tasks(cfg)
    assert not unit.done() and run_tasks([unit], ExecutorConfig(workers=2)) == [unit]
    assert lattice_tasks(cfg)[0].done()  # (the cache key differs: scene textures live in the cache)
    a, b = torch.load(here.result, weights_only=True), torch.load(unit.result, weights_only=True)
    assert all(torch.equal(a[key], b[key]) for key in ("frames", "counts", "descriptors"))


class NoiseRenderer:
    """A stand-in renderer: seeded noise for each node, no Mitsuba."""

    center = np.zeros(3)

    def render_rgb(self, c2w, seed: int) -> np.ndarray:
        return np.random.default_rng(seed).integers(0, 256, (48, 64, 3), dtype=np.uint8)


def test_lattice_cache_entry_is_written_by_one_run_and_a_failing_write_only_warns(tmp_path, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    grid = LatticeConfig(enabled=True, lattice_radii=1, lattice_azimuths=2, lattice_elevations=1)
    cfg = config(grid, camera=UAVCamera(64, 48), obs_size=16,
                 bov=BoVConfig(sift=FeatureConfig(backend="opencv")))
    scene, features = cfg.scenes.specs()[0].load(), cfg.bov.feature_config()
    path = lattice_path(scene, cfg, features, select_variant(cfg.render.variant).variant())

    def build() -> ViewLattice:
        return build_lattice(scene, NoiseRenderer, cfg, features, progress=False)

    holder = hold(path)  # another run rendering this very lattice
    try:
        busy = build()
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
        holder.stdout.close()
    assert not path.exists()  # left to the run that holds it
    with monkeypatch.context() as full_disk:
        full_disk.setattr(Path, "write_bytes", lambda *a, **k: (_ for _ in ()).throw(ENOSPC))
        with pytest.warns(UserWarning, match=rf"^cache {path} not written \(no space left on device \(ENO"):
            full = build()
    assert not path.exists()
    build()
    cached = build_lattice(scene, lambda: pytest.fail("rendered a cached lattice"), cfg, features,
                           progress=False)
    for lattice in (busy, full):
        assert np.array_equal(lattice.frames, cached.frames)
        assert all(torch.equal(lattice.observe(i)[1], cached.observe(i)[1]) for i in range(2))
