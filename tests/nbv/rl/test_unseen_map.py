"""The privileged unseen map (`EnvConfig.privileged_unseen`): its bins against hand-placed samples, its
values against counted ones, its place in the `bov` vector over an episode (it sums to 36 x the unseen
share the env tracks), blank images leaving it as it is, and a policy that reads it refused at shipping."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from tensordict import TensorDict

from nbv.rl.bov_observation import BOV_KEY, bov_observation_size
from nbv.rl.checkpoint import save_policy
from nbv.rl.env import NBVEnv
from nbv.rl.members import export_run
from nbv.rl.unseen_map import UNSEEN_AZIMUTHS, UNSEEN_MAP_SIZE, sample_bins, unseen_map
from tests.nbv.rl.test_bov_observation import ACTIONS, config


def test_a_sample_falls_in_the_sector_of_its_azimuth_and_the_band_of_its_height():
    center = np.array([1.0, 2.0, 0.5])
    azimuths = np.radians([15.0, 45.0, 100.0, 200.0, 359.0])
    heights = np.array([0.0, 1.0, 2.9, 1.5, 3.0])  # the lowest and the highest sample span 3 m
    samples = center + np.stack([np.cos(azimuths), np.sin(azimuths), heights - 0.5], axis=1)
    bins = sample_bins(samples, center)
    # sectors 0, 1, 3, 6, 11; bands 0 (below 1 m), 1 (1 to 2 m), 2 (2 m and up, the top included)
    assert bins.tolist() == [0, UNSEEN_AZIMUTHS + 1, 2 * UNSEEN_AZIMUTHS + 3, UNSEEN_AZIMUTHS + 6,
                             2 * UNSEEN_AZIMUTHS + 11]


def test_each_bin_counts_its_unseen_samples_over_an_average_bin():
    bins = np.array([0, 0, 0, 5, 5, 35, 35, 35, 35])
    seen = np.array([True, False, False, False, True, True, True, True, True])
    values = unseen_map(bins, seen)
    average = 9 / UNSEEN_MAP_SIZE
    assert values.dtype == np.float32 and values.shape == (UNSEEN_MAP_SIZE,)
    assert values[0] == pytest.approx(2 / average) and values[5] == pytest.approx(1 / average)
    assert np.count_nonzero(values) == 2  # bin 35 is all seen
    assert values.sum() == pytest.approx(UNSEEN_MAP_SIZE * 3 / 9)
    with pytest.raises(ValueError, match="one entry per surface sample"):
        unseen_map(bins, seen[:-1])


def test_the_env_ends_its_bov_vector_in_the_map_of_what_it_has_not_seen():
    env = NBVEnv(config(bov_observation=True, privileged_unseen=True), seed=3)
    assert bov_observation_size(env.config) == bov_observation_size(config(bov_observation=True)) + 36
    state, shares = env.reset(), []
    for action in ACTIONS:
        unseen = state[BOV_KEY][-UNSEEN_MAP_SIZE:].numpy()
        assert unseen.sum() / UNSEEN_MAP_SIZE == pytest.approx(1.0 - env._seen.mean(), abs=1e-5)
        shares.append(1.0 - env._seen.mean())
        state = env.step(TensorDict({"action": torch.tensor(action)}, []))["next"]
    assert shares[0] > shares[-1] and all(a >= b for a, b in zip(shares, shares[1:]))  # it only empties
    blind = NBVEnv(config(bov_observation=True, privileged_unseen=True), seed=3, blank_images=True)
    blind.reset()
    for action in ACTIONS:
        out = blind.step(TensorDict({"action": torch.tensor(action)}, []))["next"]
    np.testing.assert_array_equal(out[BOV_KEY][-UNSEEN_MAP_SIZE:], state[BOV_KEY][-UNSEEN_MAP_SIZE:])


def test_the_map_needs_the_bov_vector():
    with pytest.raises(ValueError, match="privileged_unseen extends the Bag of Views vector"):
        config(privileged_unseen=True)


def test_a_policy_that_reads_the_true_mesh_never_ships(tmp_path):
    save_policy(tmp_path / "policy.pt", '{"env": {"privileged_unseen": true}, "logger": {"out": "x"}}',
                {"actor_network_params.w": torch.zeros(2)}, {"frames": 0, "updates": 0})
    with pytest.raises(ValueError, match="reads the true mesh"):
        export_run(tmp_path, tmp_path / "shipped", "runs/default")
    assert not (tmp_path / "shipped").exists()


def test_a_resumed_episode_carries_the_map():
    env = NBVEnv(config(bov_observation=True, privileged_unseen=True), seed=5)
    env.reset()
    env.step(TensorDict({"action": torch.tensor(ACTIONS[1])}, []))
    again = NBVEnv(config(bov_observation=True, privileged_unseen=True), seed=0)
    again.restore(env.snapshot())  # a new env: no samples loaded yet when the resumed state is read
    np.testing.assert_array_equal(again.reset()[BOV_KEY], env._observation()[BOV_KEY])
