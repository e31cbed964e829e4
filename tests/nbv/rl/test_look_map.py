"""The look map (`EnvConfig.look_map`): its values against hand-worked directions, its growth over an
episode as a running maximum of the views flown, its place in the `bov` vector, and that blank images
leave it as it is."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from tensordict import TensorDict

from nbv.rl.bov_observation import BOV_KEY, bov_observation_size
from nbv.rl.env import NBVEnv
from nbv.rl.look_map import LOOK_AZIMUTHS, LOOK_MAP_SIZE, look_directions, look_map, look_of
from render.viewpoint import Viewpoint
from tests.nbv.rl.test_bov_observation import ACTIONS, config


def test_the_directions_are_unit_rings_then_straight_up():
    directions = look_directions()
    assert directions.shape == (LOOK_MAP_SIZE, 3) == (37, 3)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0)
    np.testing.assert_allclose(directions[3], [0.0, 1.0, 0.0], atol=1e-12)  # ring 0, azimuth 90 degrees
    np.testing.assert_allclose(directions[LOOK_AZIMUTHS], [math.sqrt(3) / 2, 0.0, 0.5])  # 30 degrees up
    np.testing.assert_allclose(directions[-1], [0.0, 0.0, 1.0])


def test_a_view_scores_each_direction_by_its_cosine_and_nothing_behind_it():
    values = look_of(Viewpoint(2.0, 0.0, 0.0))  # on the x axis, level
    assert values[0] == pytest.approx(1.0)  # the wall it faces, head-on
    assert values[2] == pytest.approx(0.5)  # 60 degrees round
    assert values[3] == pytest.approx(0.0, abs=1e-7)  # side-on
    assert values[6] == 0.0  # the far wall: behind, not negative
    assert values[LOOK_AZIMUTHS] == pytest.approx(math.sqrt(3) / 2)  # 30-degree roof facing it
    assert values[-1] == pytest.approx(0.0, abs=1e-7)  # the flat roof, side-on
    high = look_of(Viewpoint(1.5, math.pi, math.radians(60.0)))  # the radius plays no part
    assert high[-1] == pytest.approx(math.sqrt(3) / 2)
    assert high[6] == pytest.approx(0.5)  # the wall at azimuth 180 from 60 degrees up


def test_the_map_of_several_views_is_their_running_maximum():
    views = [Viewpoint(2.0, 0.0, 0.1), Viewpoint(2.0, 2.0, 0.8), Viewpoint(1.7, 4.0, 0.3)]
    expected = np.maximum(np.maximum(look_of(views[0]), look_of(views[1])), look_of(views[2]))
    np.testing.assert_array_equal(look_map(views), expected)
    np.testing.assert_array_equal(look_map([]), np.zeros(LOOK_MAP_SIZE))


def test_the_env_ends_its_bov_vector_in_the_map_of_the_views_flown():
    env = NBVEnv(config(bov_observation=True, look_map=True), seed=3)
    assert bov_observation_size(env.config) == bov_observation_size(config(bov_observation=True)) + 37
    state, views = env.reset(), [env.viewpoint]
    np.testing.assert_allclose(state[BOV_KEY][-LOOK_MAP_SIZE:].numpy(), look_map(views))
    for action in ACTIONS:
        state = env.step(TensorDict({"action": torch.tensor(action)}, []))["next"]
        views.append(env.viewpoint)
        np.testing.assert_allclose(state[BOV_KEY][-LOOK_MAP_SIZE:].numpy(), look_map(views))
    blind = NBVEnv(config(bov_observation=True, look_map=True), seed=3, blank_images=True)
    blind.reset()
    for action in ACTIONS:
        out = blind.step(TensorDict({"action": torch.tensor(action)}, []))["next"]
    np.testing.assert_array_equal(out[BOV_KEY][-LOOK_MAP_SIZE:], state[BOV_KEY][-LOOK_MAP_SIZE:])


def test_a_snapshot_carries_the_map():
    env = NBVEnv(config(bov_observation=True, look_map=True), seed=5)
    env.reset()
    env.step(TensorDict({"action": torch.tensor(ACTIONS[1])}, []))
    again = NBVEnv(config(bov_observation=True, look_map=True), seed=0)
    again.restore(env.snapshot())
    np.testing.assert_array_equal(again.reset()[BOV_KEY], env._observation()[BOV_KEY])


def test_the_map_needs_the_bov_vector():
    with pytest.raises(ValueError, match="look_map extends the Bag of Views vector"):
        config(look_map=True)
