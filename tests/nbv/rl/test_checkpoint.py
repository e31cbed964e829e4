"""Checkpoints: RNG round trip, atomic save, corrupt / foreign / mismatched files rejected clearly."""

from __future__ import annotations

import random

import numpy as np
import pytest
import torch

from nbv.rl.checkpoint import (
    CheckpointError,
    check_compatible,
    load_checkpoint,
    load_policy,
    rng_state,
    save_checkpoint,
    save_policy,
    set_rng_state,
)


def minimal_state() -> dict:
    return {"config": "{}", "loss": {"w": torch.ones(2)}, "optim_actor": {}, "optim_critic": {}, "buffer": {},
            "counters": {"frames": 0, "updates": 0}, "rng": rng_state()}


def test_rng_states_round_trip_through_a_weights_only_file(tmp_path):
    torch.manual_seed(1), np.random.seed(2), random.seed(3)
    path = save_checkpoint(tmp_path / "c.pt", minimal_state())
    expected = (torch.rand(3), np.random.rand(3), random.random())
    torch.manual_seed(9), np.random.seed(9), random.seed(9)
    set_rng_state(load_checkpoint(path)["rng"])
    got = (torch.rand(3), np.random.rand(3), random.random())
    assert torch.equal(got[0], expected[0]) and np.array_equal(got[1], expected[1]) and got[2] == expected[2]


def test_truncated_checkpoint_is_a_clear_error(tmp_path):
    path = save_checkpoint(tmp_path / "c.pt", minimal_state())
    path.write_bytes(path.read_bytes()[:100])
    with pytest.raises(CheckpointError, match="corrupt"):
        load_checkpoint(path)


def test_foreign_and_incomplete_files_are_rejected(tmp_path):
    torch.save({"weights": torch.zeros(1)}, tmp_path / "other.pt")
    with pytest.raises(CheckpointError, match="not an nbv SAC checkpoint"):
        load_checkpoint(tmp_path / "other.pt")
    state = minimal_state()
    del state["buffer"]
    save_checkpoint(tmp_path / "partial.pt", state)
    with pytest.raises(CheckpointError, match="lacks buffer"):
        load_checkpoint(tmp_path / "partial.pt")
    with pytest.raises(CheckpointError, match="not found"):
        load_checkpoint(tmp_path / "missing.pt")


def test_pickled_code_is_refused(tmp_path):
    torch.save({"format": "nbv-sac-checkpoint", "payload": object()}, tmp_path / "evil.pt")
    with pytest.raises(CheckpointError, match="corrupt or not a checkpoint"):
        load_checkpoint(tmp_path / "evil.pt")


def test_mismatched_settings_are_listed():
    saved = {"env": {"obs_size": 64, "scene": ["a"]}, "collector": {"frames": 100}}
    check_compatible("c.pt", saved, {"env": {"obs_size": 64, "scene": ["a"]}, "collector": {"frames": 500}},
                     free=("collector.frames",))
    current = {"env": {"obs_size": 32, "scene": ["a"]}, "collector": {"frames": 100}}
    with pytest.raises(CheckpointError, match=r"env.obs_size: checkpoint 64, now 32"):
        check_compatible("c.pt", saved, current, free=("collector.frames",))


def test_policy_file_holds_the_actor_alone(tmp_path):
    loss = {"actor_network_params.module.0.weight": torch.ones(2), "qvalue_network_params.w": torch.zeros(3)}
    state = {**minimal_state(), "config": '{"env": {}}', "loss": loss}
    save_checkpoint(tmp_path / "checkpoint.pt", state)
    save_policy(tmp_path / "policy.pt", state["config"], loss, state["counters"])
    raw = torch.load(tmp_path / "policy.pt", weights_only=True)  # an independent reader: plain torch
    assert raw["format"] == "nbv-sac-policy" and set(raw["actor"]) == {"module.0.weight"}
    for path in ("policy.pt", "checkpoint.pt"):  # either file gives the same config and actor
        config, weights = load_policy(tmp_path / path)
        assert config == {"env": {}} and set(weights) == {"module.0.weight"}
    with pytest.raises(CheckpointError, match="not an nbv SAC checkpoint"):
        load_checkpoint(tmp_path / "policy.pt")  # resuming training needs the whole checkpoint
    torch.save({"weights": torch.zeros(1)}, tmp_path / "other.pt")
    with pytest.raises(CheckpointError, match="not an nbv policy file or an nbv SAC checkpoint"):
        load_policy(tmp_path / "other.pt")
