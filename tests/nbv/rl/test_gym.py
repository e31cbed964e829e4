"""NBVGymEnv: Gymnasium's checker passes, spaces match the config, seeded rollouts repeat exactly."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
from nbv.rl.config import EnvConfig
from nbv.rl.gym import NBVGymEnv
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.spec import SceneSet


def tiny_config(**kwargs) -> EnvConfig:
    """64x48 renders at 1 spp, 16x16 frames, OpenCV SIFT, 3-step episodes."""
    settings = dict(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                    render=RenderSettings(spp=1),
                    bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")),
                    obs_size=16, max_steps=3)
    return EnvConfig(**{**settings, **kwargs})


def rollout(env: NBVGymEnv, seed: int, steps: int) -> list:
    """(observation, reward, terminated, truncated, info) of a seeded episode with seeded random actions."""
    obs, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    out = [(obs, info)]
    for _ in range(steps):
        out.append(env.step(env.action_space.sample()))
    return out


def test_gymnasium_checker_passes():
    env = NBVGymEnv(tiny_config())
    check_env(env, skip_render_check=True)  # no render modes
    env.close()


def test_spaces_and_step_values():
    env = NBVGymEnv(tiny_config(history=4))
    assert env.observation_space["pixels"].shape == (4, 16, 16)
    assert env.observation_space["viewpoints"].shape == (4, 3)
    obs, info = env.reset(seed=3)
    assert obs in env.observation_space and info["viewpoint"].shape == (3,)
    obs, reward, terminated, truncated, _ = env.step(np.array([1.0, -1.0, 1.0], dtype=np.float32))
    np.testing.assert_allclose(obs["viewpoints"][-1], [1.0, -1.0, 1.0], atol=1e-6)
    assert isinstance(reward, float) and not terminated and not truncated
    with pytest.raises(ValueError, match="outside|\\[-1, 1\\]"):
        env.step(np.array([2.0, 0.0, 0.0], dtype=np.float32))


def assert_same(first: list, again: list) -> None:
    for a, b in zip(first, again, strict=True):
        for x, y in zip(a, b, strict=True):
            if isinstance(x, dict):
                assert x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x)
            else:
                assert x == y


def test_seeded_rollout_is_reproducible_and_truncates():
    env = NBVGymEnv(tiny_config())
    first = rollout(env, seed=7, steps=3)
    assert_same(first, rollout(NBVGymEnv(tiny_config()), seed=7, steps=3))  # a fresh env
    assert_same(first, rollout(env, seed=7, steps=3))  # the same env, reseeded after its episode
    assert first[-1][3] or first[-1][2]  # max_steps = 3: the third step ends the episode
    other = rollout(NBVGymEnv(tiny_config()), seed=8, steps=1)
    assert not np.array_equal(other[0][0]["viewpoints"], first[0][0]["viewpoints"])
