"""NBVEnv: specs (single and parallel), reward, termination, action validation, snapshots."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
import torch
from torchrl.envs.utils import check_env_specs

from nbv.bov.bag import BagOfViews
from nbv.bov.config import BoVConfig
from nbv.features.sift import FeatureConfig, extract_features
from nbv.rl.builders import make_environment
from nbv.rl.config import EnvConfig, RewardConfig
from nbv.rl.env import NBVEnv, action_to_viewpoint, check_action, wrap_angle
from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import LightingSettings, RenderSettings, SensorSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.spec import SceneSet


def tiny_config(width: int = 64, height: int = 48, match_cosine: float = 0.8, **kwargs) -> EnvConfig:
    """A tiny, fast env: 64x48 renders, 32x32 frames, 1 spp, OpenCV SIFT."""
    settings = dict(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(width, height),
                    render=RenderSettings(spp=1), bov=BoVConfig(ranges=8, match_cosine=match_cosine,
                                                                sift=FeatureConfig(backend="opencv")),
                    obs_size=32, max_steps=3)
    return EnvConfig(**{**settings, **kwargs})


def test_specs_single_env():
    check_env_specs(NBVEnv(tiny_config(), seed=0))


def test_specs_parallel_env_two_workers():
    env = make_environment(tiny_config(), envs=2, seed=0)
    try:
        check_env_specs(env)
        rollout = env.rollout(2, break_when_any_done=False)
        assert rollout.batch_size == (2, 2)
        assert rollout["next", "pixels"].shape == (2, 2, 5, 32, 32)
    finally:
        env.close()


def test_env_renders_with_every_render_setting():
    render = RenderSettings(spp=1, resolution_scale=0.5, lighting=LightingSettings(light_mode="overcast"),
                            sensor=SensorSettings(exposure_stops=1.0, shot_noise=0.01, jpeg_quality=40))
    env = NBVEnv(tiny_config(render=render), seed=3)
    env.reset()  # renders view 0
    image = env.render_view(env.viewpoint)
    seeded = replace(render, seed=3)
    renderer = MitsubaRenderer(load_scene("test_building"), UAVCamera(64, 48), seeded)
    expected = renderer.render_rgb(viewpoint_to_c2w(env.viewpoint, renderer.center), seed=seeded.view_seed(1))
    assert image.shape == (24, 32, 3)
    np.testing.assert_array_equal(image, expected)


def test_observation_histories():
    env = NBVEnv(tiny_config(history=4), seed=1)
    td = env.reset()
    assert td["pixels"].dtype == torch.uint8 and td["pixels"].shape == (4, 32, 32)
    assert torch.equal(td["pixels"][0], td["pixels"][-1])  # the first view repeated
    out = env.step(td.set("action", torch.tensor([1.0, -1.0, 1.0])))["next"]
    assert torch.equal(out["pixels"][:-1], td["pixels"][1:])
    assert torch.allclose(out["viewpoints"][-1], torch.tensor([1.0, -1.0, 1.0]))
    assert env.viewpoint.radius == pytest.approx(2.5) and env.viewpoint.azimuth == pytest.approx(0.0)


def test_reward_equals_bag_of_views_reward():
    config = tiny_config(width=160, height=120, max_steps=5)
    env = NBVEnv(config, seed=3)
    env.reset()
    views = [env.viewpoint]
    rewards = []
    for action in ([0.0, -0.5, 0.2], [0.5, 0.3, -0.4]):
        out = env.step(_with_action(env, action))
        views.append(env.viewpoint)
        rewards.append(float(out["next", "reward"]))

    renderer = MitsubaRenderer(load_scene("test_building"), config.camera, RenderSettings(spp=1, seed=3))
    images = [renderer.render_rgb(viewpoint_to_c2w(v, renderer.center), seed=3 * 1_000_003 + i)
              for i, v in enumerate(views)]
    descriptors = [f.descriptors for f in extract_features(images, FeatureConfig(backend="opencv"))]
    bov = BagOfViews(config.bov.ranges, config.bov.words, memory_cap=config.bov.memory_cap, seed=3)
    bov.update(descriptors[0], views[0].azimuth)
    expected = [bov.reward(d, v.azimuth) for d, v in zip(descriptors[1:], views[1:])]
    assert rewards == pytest.approx(expected, abs=1e-5)


def _with_action(env: NBVEnv, action: list[float]):
    return env.observation_spec.zero().set("action", torch.tensor(action))


def test_terminates_after_one_full_pass():
    env = NBVEnv(tiny_config(action_mode="relative", relative_step=0.25, max_steps=10), seed=0)
    td = env.reset()
    dones = []
    for _ in range(4):  # four quarter turns: net azimuth 2 pi
        td = env.step(td.set("action", torch.tensor([0.0, 1.0, 0.0])))["next"]
        dones.append((bool(td["terminated"]), bool(td["truncated"])))
    assert dones == [(False, False)] * 3 + [(True, False)]


def test_back_and_forth_does_not_terminate_but_truncates():
    env = NBVEnv(tiny_config(action_mode="relative", relative_step=0.25, max_steps=4), seed=0)
    td = env.reset()
    flags = []
    for sign in (1.0, -1.0, 1.0, -1.0):
        td = env.step(td.set("action", torch.tensor([0.0, sign, 0.0])))["next"]
        flags.append((bool(td["terminated"]), bool(td["truncated"]), bool(td["done"])))
    assert flags == [(False, False, False)] * 3 + [(False, True, True)]


def test_a_view_budget_ends_the_episode_and_a_pass_does_not():
    config = tiny_config(action_mode="relative", relative_step=0.25, max_steps=10, episode_views=6)
    env = NBVEnv(config, seed=0)
    td = env.reset()
    flags = []
    for _ in range(5):  # a full pass after four quarter turns, then a fifth step: the sixth view
        td = env.step(td.set("action", torch.tensor([0.0, 1.0, 0.0])))["next"]
        flags.append((bool(td["terminated"]), bool(td["truncated"])))
    assert flags == [(False, False)] * 4 + [(True, False)]
    with pytest.raises(ValueError, match="episode_views must be 0"):
        tiny_config(episode_views=12, max_steps=10)


@pytest.mark.parametrize("action, message", [
    ([float("nan"), 0.0, 0.0], "NaN"),
    ([1.5, 0.0, 0.0], r"\[-1, 1\]"),
    ([0.0, -1.01, 0.0], r"\[-1, 1\]"),
    ([0.0, 0.0], "3 values"),
])
def test_bad_actions_are_rejected(action, message):
    with pytest.raises(ValueError, match=message):
        check_action(torch.tensor(action))


def test_env_step_rejects_out_of_range_action():
    env = NBVEnv(tiny_config(), seed=0)
    td = env.reset()
    with pytest.raises(ValueError, match="NBV action"):
        env.step(td.set("action", torch.tensor([0.0, 2.0, 0.0])))


def test_action_rescaling_and_angle_wrap():
    config = tiny_config()
    start = Viewpoint(2.0, 0.1, 0.3)
    low = action_to_viewpoint([-1.0, -1.0, -1.0], start, config)
    assert (low.radius, low.azimuth, low.elevation) == pytest.approx((1.5, 0.0, math.radians(5)))
    mid = action_to_viewpoint([0.0, 0.0, 0.0], start, config)
    assert mid.azimuth == pytest.approx(math.pi) and mid.radius == pytest.approx(2.0)
    relative = replace(config, action_mode="relative", relative_step=0.5)
    step = action_to_viewpoint([1.0, -1.0, 0.5], start, relative)  # R and elevation clip to their ranges
    assert step.radius == pytest.approx(2.5) and step.azimuth == pytest.approx(0.1 - math.pi + 2 * math.pi)
    assert step.elevation == pytest.approx(0.3 + 0.25 * math.radians(75))
    high = action_to_viewpoint([0.0, 0.0, 1.0], Viewpoint(2.0, 0.1, 1.2), relative)
    assert high.elevation == pytest.approx(math.radians(80))
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(-math.pi) == pytest.approx(math.pi)


def test_orbit_steps_the_azimuth_and_sets_radius_and_elevation():
    orbit = replace(tiny_config(), action_mode="orbit", relative_step=0.125)
    view = action_to_viewpoint([-1.0, 1.0, 1.0], Viewpoint(2.0, 6.0, 0.3), orbit)
    assert view.radius == pytest.approx(1.5) and view.elevation == pytest.approx(math.radians(80))
    assert view.azimuth == pytest.approx(6.0 + math.pi / 4 - 2 * math.pi)  # one eighth of a turn, wrapped
    back = action_to_viewpoint([0.0, -0.5, -1.0], Viewpoint(2.0, 0.1, 0.3), orbit)
    assert back.azimuth == pytest.approx(0.1 - math.pi / 8 + 2 * math.pi)
    assert back.radius == pytest.approx(2.0)
    assert back.elevation == pytest.approx(math.radians(5))


def test_forward_always_advances_the_azimuth_and_sets_radius_and_elevation():
    forward = replace(tiny_config(), action_mode="forward", relative_step=2 / 13)
    least = action_to_viewpoint([-1.0, -1.0, -1.0], Viewpoint(2.0, 6.2, 0.3), forward)
    assert least.azimuth == pytest.approx(6.2 + 2 * math.pi / 13 - 2 * math.pi)  # half: one turn in 13 views
    assert least.radius == pytest.approx(1.5) and least.elevation == pytest.approx(math.radians(5))
    most = action_to_viewpoint([1.0, 1.0, 1.0], Viewpoint(2.0, 0.1, 0.3), forward)
    assert most.azimuth == pytest.approx(0.1 + 4 * math.pi / 13)  # the whole step: two turns in 13 views
    assert most.radius == pytest.approx(2.5) and most.elevation == pytest.approx(math.radians(80))
    middle = action_to_viewpoint([0.0, 0.0, 0.0], Viewpoint(2.0, 0.1, 0.3), forward)
    assert middle.azimuth == pytest.approx(0.1 + 3 * math.pi / 13)


def test_match_cosine_reaches_the_reward():
    """Same seed, same actions: only the Bag of Views' c differs, and so do the rewards."""
    rewards = {}
    for c in (0.5, 0.8):
        env = NBVEnv(tiny_config(match_cosine=c, action_mode="relative", max_steps=5), seed=2)
        assert env.bov.match_cosine == c
        td = env.reset()
        rewards[c] = []
        for action in ([0.0, 0.0, 0.0], [0.1, 0.02, -0.1]):  # stays in the start view's azimuth range
            td = env.step(td.set("action", torch.tensor(action)))["next"]
            rewards[c].append(float(td["reward"]))
    assert all(math.isfinite(r) for r in rewards[0.5] + rewards[0.8])
    assert rewards[0.5] != pytest.approx(rewards[0.8], abs=1e-3)


@pytest.mark.parametrize("coverage_reward", [0.0, 30.0])  # with the coverage term: what was seen, too
def test_snapshot_restore_continues_the_episode(coverage_reward):
    config, terms = tiny_config(max_steps=6), RewardConfig(coverage=coverage_reward)
    a = NBVEnv(config, seed=5, reward_terms=terms)
    td = a.reset()
    td = a.step(td.set("action", torch.tensor([0.2, 0.4, -0.1])))["next"]
    b = NBVEnv(config, seed=99, reward_terms=terms)
    b.restore(a.snapshot())
    resumed = b.reset()
    assert torch.equal(resumed["pixels"], td["pixels"])
    assert torch.equal(resumed["viewpoints"], td["viewpoints"])
    action = torch.tensor([-0.3, 0.9, 0.5])
    out_a = a.step(td.clone().set("action", action))["next"]
    out_b = b.step(resumed.set("action", action))["next"]
    assert torch.equal(out_a["pixels"], out_b["pixels"])
    assert float(out_a["reward"]) == float(out_b["reward"])
    np.testing.assert_array_equal(a.snapshot()["frames"], b.snapshot()["frames"])


def test_a_restored_episode_continues_its_return():
    from torchrl.envs import TransformedEnv

    from nbv.rl.episode_return import EpisodeReturn

    config = tiny_config(max_steps=6)
    a = TransformedEnv(NBVEnv(config, seed=5), EpisodeReturn())
    td = a.reset()
    rewards = []
    for action in ([0.2, 0.4, -0.1], [0.0, -0.5, 0.3]):
        td = a.step(td.set("action", torch.tensor(action)))["next"]
        rewards.append(td["reward"])
    assert torch.equal(td["episode_reward"], rewards[0] + rewards[1]) and float(td["episode_reward"]) != 0
    b = TransformedEnv(NBVEnv(config, seed=99), EpisodeReturn())
    b.base_env.restore(a.base_env.snapshot())
    resumed = b.reset()
    assert torch.equal(resumed["episode_reward"], td["episode_reward"])  # not restarted at 0
    action = torch.tensor([-0.3, 0.9, 0.5])
    out_a, out_b = a.step(td.set("action", action))["next"], b.step(resumed.set("action", action))["next"]
    assert torch.equal(out_a["episode_reward"], out_b["episode_reward"])
    assert float(b.reset()["episode_reward"]) == 0.0  # a new episode starts at 0


def test_a_training_env_renders_a_view_the_same_every_time():
    import drjit as dr

    from nbv.rl.builders import RENDER_THREADS, training_env

    before = dr.thread_count()
    try:
        env = training_env(tiny_config(32, 24), 0, 0, RewardConfig())
        assert dr.thread_count() == RENDER_THREADS == 1
        env.reset()
        renderer = env.source.renderer(env.source.spec)
        rng = np.random.default_rng(0)
        poses = [viewpoint_to_c2w(Viewpoint(rng.uniform(1.5, 3), rng.uniform(0, 6.28), rng.uniform(0.1, 1)),
                                  renderer.center) for _ in range(10)]
        # The float images before quantisation: on 2 threads 2-10 % of these passes differed by 1 ulp.
        first = [renderer._mean_pass([pose], k, renderer._rgb_integrator) for k, pose in enumerate(poses)]
        for _ in range(3):
            for k, pose in enumerate(poses):
                assert np.array_equal(first[k], renderer._mean_pass([pose], k, renderer._rgb_integrator))
    finally:
        dr.set_thread_count(before)


def test_env_puts_torch_on_the_thread_policy_when_it_first_renders(monkeypatch):
    from common import threads

    before = torch.get_num_threads()
    monkeypatch.setattr(threads, "_chosen", None)
    try:
        torch.set_num_threads(2)
        env = NBVEnv(tiny_config(), seed=0)
        assert torch.get_num_threads() == 2  # the constructor runs in the parent: it sets nothing
        env.reset()
        assert torch.get_num_threads() == threads.worker_threads() == 1
    finally:
        torch.set_num_threads(before)


def test_env_keeps_threads_the_process_chose(monkeypatch):
    from common import threads

    before = torch.get_num_threads()
    monkeypatch.setattr(threads, "_chosen", None)
    try:
        threads.set_torch_threads(2)  # e.g. `nbv train --threads 2` with an in-process env
        NBVEnv(tiny_config(), seed=0).reset()
        assert torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)
