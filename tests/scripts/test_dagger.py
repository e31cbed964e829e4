"""`scripts/dagger.py`'s pieces on synthetic states: the replay buffer read back, the fit to the labels."""

from __future__ import annotations

import importlib.util
from collections import OrderedDict
from pathlib import Path

import pytest
import torch
from tensordict import TensorDict

from nbv.rl.builders import make_sac_agent
from nbv.rl.config import EnvConfig, NetworkConfig
from nbv.rl.expert import EXPERT_KEY
from nbv.rl.train import mode_distance
from scenes.spec import SceneSet

ROOT = Path(__file__).resolve().parents[2]


def dagger():
    spec = importlib.util.spec_from_file_location("dagger", ROOT / "scripts" / "dagger.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def states(count: int, label: list[float]) -> list[TensorDict]:
    gen = torch.Generator().manual_seed(0)
    return [TensorDict({"pixels": torch.randint(0, 255, (5, 16, 16), generator=gen, dtype=torch.uint8),
                        "viewpoints": torch.rand(5, 3, generator=gen) * 2 - 1,
                        EXPERT_KEY: torch.tensor(label)}, []) for _ in range(count)]


def test_buffer_states_reads_the_newest_labelled_states_of_a_checkpoint(tmp_path):
    items = [OrderedDict(pixels=torch.full((5, 16, 16), i, dtype=torch.uint8), viewpoints=torch.zeros(5, 3),
                         expert_action=torch.full((3,), i / 10), reward=torch.ones(1)) for i in range(4)]
    torch.save({"buffer": {"_storage": {"_storage": items}}}, tmp_path / "checkpoint.pt")
    read = dagger().buffer_states(tmp_path / "checkpoint.pt", ["pixels", "viewpoints", EXPERT_KEY], 2)
    assert [int(s["pixels"][0, 0, 0]) for s in read] == [2, 3]  # the two newest
    assert set(read[0].keys()) == {"pixels", "viewpoints", EXPERT_KEY}
    assert len(dagger().buffer_states(tmp_path / "checkpoint.pt", ["pixels"], 0)) == 4


def test_fitting_brings_the_mode_to_the_teachers_labels_on_states_never_fitted():
    module = dagger()
    torch.manual_seed(0)
    env = EnvConfig(scenes=SceneSet(scene=("test_building",)), obs_size=16)
    actor, _ = make_sac_agent(env, NetworkConfig(channels=4, hidden=16, location_hidden=8))
    label = [0.5, -0.5, 0.25]
    data, held = torch.stack(states(32, label)), torch.stack(states(8, label))
    before = mode_distance(actor, held).item()
    passes = module.fit(actor, torch.optim.Adam(actor.parameters(), lr=1e-2), data, held, 30, 8,
                        torch.Generator().manual_seed(0))
    assert len(passes) == 30 and passes[-1]["train"] < passes[0]["train"]
    assert passes[-1]["held"] < 0.05 < before


def test_its_training_config_is_nbv_trains_for_the_same_preset_and_buildings(tmp_path):
    from common.provenance import config_record
    from nbv.cli.train import parse_train

    scenes = ["medieval_tavern", "family:22", "random:9"]
    flags = [arg for scene in scenes for arg in ("--scene", scene)]
    made = dagger().train_config("default", scenes, tmp_path)
    assert config_record(made) == config_record(parse_train([*flags, "--out", str(tmp_path)]))
    assert config_record(dagger().train_config("paper", [], tmp_path)) == config_record(
        parse_train(["--preset", "paper", "--out", str(tmp_path)]))
    assert config_record(dagger().train_config("default", [], tmp_path, privileged=True)) == config_record(
        parse_train(["--privileged-unseen", "--out", str(tmp_path)]))


def test_strip_unseen_cuts_the_map_from_one_state_and_from_a_stack():
    module = dagger()
    one = TensorDict({"bov": torch.arange(40.0)}, [])
    assert module.strip_unseen(one)["bov"].tolist() == list(range(4))
    stack = TensorDict({"bov": torch.ones(3, 40)}, [3])
    assert module.strip_unseen(stack)["bov"].shape == (3, 4)


def test_the_map_cannot_be_both_read_and_cut():
    with pytest.raises(SystemExit, match="--strip-unseen fits an actor without the unseen map"):
        dagger().arguments(["--out", "x", "--privileged-unseen", "--strip-unseen"])
