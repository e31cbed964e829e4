"""Checkpoints: RNG round trip, atomic save, corrupt / foreign / mismatched files rejected clearly."""

from __future__ import annotations

import math
import random
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
import torch

from nbv.rl.checkpoint import (
    CheckpointError,
    check_compatible,
    copy_policy,
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


def _policy_with_weights(path, weights: torch.Tensor):
    return save_policy(path, '{"env": {}}', {"actor_network_params.w": weights}, {"frames": 0, "updates": 0})


def _zero_bytes_inside(path, tensor: torch.Tensor) -> None:
    """Zero 64 bytes in the middle of `tensor`'s bytes in the file (the probe's damage, F20)."""
    data = bytearray(path.read_bytes())
    start = data.find(tensor.numpy().tobytes())
    assert start > 0
    middle = start + tensor.numel() * 2
    data[middle:middle + 64] = bytes(64)
    path.write_bytes(bytes(data))


def test_zeroed_weight_bytes_refused(tmp_path):
    weights = torch.from_numpy(np.random.default_rng(0).standard_normal(4096).astype(np.float32))
    path = _policy_with_weights(tmp_path / "policy.pt", weights)
    assert torch.equal(load_policy(path)[1]["w"], weights)
    _zero_bytes_inside(path, weights)
    with pytest.raises(CheckpointError, match=r"policy.pt: its zip archive is corrupt \(Bad CRC-32"):
        load_policy(path)


def test_zeroed_weight_bytes_refused_by_the_checksum_without_crcs(tmp_path):
    """A file written without zip CRCs (torch's option) is still caught by the tensor checksum it carries."""
    weights = torch.from_numpy(np.random.default_rng(1).standard_normal(4096).astype(np.float32))
    torch.serialization.set_crc32_options(False)
    try:
        path = _policy_with_weights(tmp_path / "policy.pt", weights)
    finally:
        torch.serialization.set_crc32_options(True)
    _zero_bytes_inside(path, weights)
    with pytest.raises(CheckpointError, match="policy.pt is corrupt: its tensors do not match the checksum"):
        load_policy(path)


def test_policy_without_checksum_loads_with_a_warning(tmp_path):
    weights = torch.ones(3)
    path = _policy_with_weights(tmp_path / "policy.pt", weights)
    state = torch.load(path, weights_only=True)
    del state["checksum"]
    torch.save(state, path)
    with pytest.warns(UserWarning, match="policy.pt carries no tensor checksum"):
        assert torch.equal(load_policy(path)[1]["w"], weights)


@pytest.mark.parametrize("path", ["nbv/planning/shipped/policy.pt", "nbv/planning/shipped/paper/policy.pt",
                                  "nbv/planning/shipped/coverage/policy.pt",
                                  "paper_results/online/policies/seed1/policy.pt",
                                  "paper_results/online/policies/seed2/policy.pt"])
def test_shipped_policies_carry_their_checksum(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        state = load_checkpoint(Path(__file__).parents[3] / path, ("nbv-sac-policy",))
    assert len(state["checksum"]) == 64


def test_zip_bomb_refused_before_decompression(tmp_path):
    """A 16 MiB entry deflated to ~16 kB: refused from the central directory, before anything inflates."""
    path = tmp_path / "bomb.pt"
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("archive/data.pkl", bytes(16 * 2**20))
    assert path.stat().st_size < 2**20
    with pytest.raises(CheckpointError,
                       match=r"bomb.pt: its zip entries inflate to 16777216 bytes from \d+ on disk "
                             r"\(1 compressed"):
        load_policy(path)


def test_all_nan_weights_refused(tmp_path):
    path = _policy_with_weights(tmp_path / "policy.pt", torch.full((8,), math.nan))
    with pytest.raises(CheckpointError, match=r"policy.pt: actor weights w hold NaN or infinite values"):
        load_policy(path)


def test_unknown_enum_value_refused(tmp_path):
    """`env.action_mode: "teleport"` in a policy's config: refused naming the field (PolicyPlanner turns it
    into a CheckpointError naming the file), not planned as relative."""
    from common.provenance import config_from_record
    from nbv.planning.registry import SHIPPED_POLICY
    from nbv.rl.config import EnvConfig

    config, _ = load_policy(SHIPPED_POLICY)  # in today's layout
    assert config_from_record(EnvConfig, config["env"]).action_mode in ("absolute", "relative", "orbit")
    config["env"]["action_mode"] = "teleport"
    saved, _ = load_policy(copy_policy(SHIPPED_POLICY, tmp_path / "teleport.pt", config))
    with pytest.raises(ValueError, match="EnvConfig field action_mode is 'teleport', not one of 'absolute', "
                                         "'relative', 'orbit'"):
        config_from_record(EnvConfig, saved["env"])
