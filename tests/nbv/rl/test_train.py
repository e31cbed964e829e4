"""`nbv train`: tiny runs that checkpoint and resume; one worker resumes bit for bit."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import replace

import pytest
import torch
from PIL import Image
from tensordict import TensorDict

from common.provenance import config_from_record, config_record
from nbv.bov.config import BoVConfig
from nbv.cli import main
from nbv.features.config import FeatureConfig
from nbv.rl.builders import make_loss_module, make_optimizers, make_sac_agent
from nbv.rl.checkpoint import CheckpointError, load_checkpoint, load_policy, save_checkpoint
from nbv.rl.config import (
    CollectorConfig,
    EnvConfig,
    LoggerConfig,
    OptimConfig,
    RewardConfig,
    TrainConfig,
    upgrade_record,
)
from nbv.rl.train import sac_update, train_run, with_defaults
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.spec import SceneSet

TINY_ENV = ["--scene", "test_building", "--width", "64", "--height", "48", "--spp", "1", "--obs-size", "32",
            "--max-steps", "3", "--episode-views", "0", "--feature-backend", "opencv",
            "--members", "1", "--validation-scenes"]  # one-pass episodes of <= 3 steps; one seed, unvalidated


def tiny(out, frames: int, **collector) -> TrainConfig:
    env = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                    render=RenderSettings(spp=1),
                    bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")), obs_size=32,
                    max_steps=3)
    settings = {"frames": frames, "frames_per_batch": 2, "init_random_frames": 2, "seed": 7, **collector}
    return TrainConfig(env=env, collector=CollectorConfig(**settings),
                       logger=LoggerConfig(out=out, checkpoint_every=1000, progress=False))


def test_one_worker_interrupted_and_resumed_equals_uninterrupted(tmp_path):
    train_run(tiny(tmp_path / "straight", 8))
    train_run(tiny(tmp_path / "resumed", 4))
    middle = load_checkpoint(tmp_path / "resumed" / "checkpoint.pt")
    assert middle["counters"]["frames"] == 4 and middle["env"]["steps"] == 1  # stopped mid-episode
    train_run(tiny(tmp_path / "resumed", 8))
    train_run(tiny(tmp_path / "resumed", 8))  # budget spent: a no-op
    a = load_checkpoint(tmp_path / "straight" / "checkpoint.pt")
    b = load_checkpoint(tmp_path / "resumed" / "checkpoint.pt")
    assert a["counters"] == b["counters"] == {"frames": 8, "updates": 8}
    assert a["loss"].keys() == b["loss"].keys()
    for key in a["loss"]:
        assert torch.equal(a["loss"][key], b["loss"][key]), key
    assert torch.equal(a["rng"]["torch"], b["rng"]["torch"])
    assert_same(a["buffer"], b["buffer"])  # the resumed episode's return (episode_reward) included
    assert logged(tmp_path / "straight") == logged(tmp_path / "resumed")
    assert [row["episode_return"] for row in logged(tmp_path / "resumed")][1:3] != ["", ""]


def assert_same(a, b, where: str = "") -> None:
    """Nested dicts, lists and tensors `a` and `b` are equal, bit for bit (NaN equal to NaN)."""
    assert type(a) is type(b), where
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            assert_same(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, list | tuple):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, torch.Tensor):
        assert torch.equal(a, b) or torch.allclose(a, b, rtol=0, atol=0, equal_nan=True), where
    else:
        assert a == b, where


TIMING = ("collect_s", "update_s")
"""Wall-clock columns of metrics.csv: the only ones a resumed run may log differently."""


def logged(run) -> list[dict]:
    """A run's metrics.csv rows without the timing columns (read with the csv module)."""
    with open(run / "metrics.csv", newline="") as file:
        return [{k: v for k, v in row.items() if k not in TIMING} for row in csv.DictReader(file)]


def test_two_worker_cli_run_writes_checkpoint_and_resumes(tmp_path):
    run = tmp_path / "run"
    args = ["train", *TINY_ENV, "--envs", "2", "--frames-per-batch", "2", "--init-random-frames", "2",
            "--out", str(run), "--no-progress"]
    assert main([*args, "--frames", "4"]) == 0
    assert load_checkpoint(run / "checkpoint.pt")["counters"]["frames"] == 4
    assert main([*args, "--frames", "8"]) == 0
    state = load_checkpoint(run / "checkpoint.pt")
    assert state["counters"] == {"frames": 8, "updates": 8}
    assert "env" not in state  # parallel workers' episodes are not checkpointed
    with open(run / "metrics.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["frames"]) for r in rows] == [2, 4, 6, 8]
    assert any((run / "tensorboard").iterdir())
    assert Image.open(run / "training.png").size[0] > 500


def replay_sample(config: TrainConfig, rewards: torch.Tensor) -> TensorDict:
    """A replay batch of identical grey states and zero actions with the given (n, 1) rewards."""
    n, side = len(rewards), config.env.obs_size
    state = {"pixels": torch.full((n, 5, side, side), 100, dtype=torch.uint8),
             "viewpoints": torch.zeros(n, 5, 3)}
    return TensorDict({**state, "action": torch.zeros(n, 3), "next": TensorDict({
        **state, "reward": rewards, "done": torch.zeros(n, 1, dtype=torch.bool),
        "terminated": torch.zeros(n, 1, dtype=torch.bool)}, [n])}, [n])


def test_reward_scale_is_the_same_update_as_scaled_rewards():
    config = tiny(None, 10)

    def one_update(rewards_times: float, reward_scale: float) -> list[torch.Tensor]:
        torch.manual_seed(0)
        actor, critic = make_sac_agent(config.env, config.network)
        loss, _ = make_loss_module(actor, critic, config.optim)
        optim_actor, optim_critic = make_optimizers(loss, config.optim)
        sample = replay_sample(config, torch.arange(4, dtype=torch.float32)[:, None] * rewards_times)
        sac_update(loss, optim_actor, optim_critic, sample, reward_scale)
        return [p.detach().clone() for p in loss.qvalue_network_params.values(True, True)]

    scaled = one_update(1.0, 0.1)
    assert all(torch.equal(a, b) for a, b in zip(scaled, one_update(0.1, 1.0)))
    assert not all(torch.equal(a, b) for a, b in zip(scaled, one_update(1.0, 1.0)))


def test_auto_alpha_learns_the_temperature_and_fixed_alpha_keeps_it():
    def alphas(auto: bool) -> list[float]:
        torch.manual_seed(0)
        config = replace(tiny(None, 10), optim=OptimConfig(auto_alpha=auto))
        actor, critic = make_sac_agent(config.env, config.network)
        loss, _ = make_loss_module(actor, critic, config.optim)
        optim_actor, optim_critic = make_optimizers(loss, config.optim)
        sample = replay_sample(config, torch.ones(4, 1))
        return [sac_update(loss, optim_actor, optim_critic, sample.clone())["alpha"] for _ in range(3)]

    assert alphas(False) == pytest.approx([0.2] * 3)
    learned = alphas(True)
    # The untrained policy's entropy (about 2) is above the target -3: log alpha falls by lr each step.
    assert learned[0] == pytest.approx(0.2) and learned[2] < learned[1] < learned[0]
    assert learned[1] == pytest.approx(0.2 * math.exp(-5e-4), rel=1e-4)


def test_resuming_with_other_settings_is_refused(tmp_path):
    train_run(tiny(tmp_path / "run", 2))
    with pytest.raises(CheckpointError, match="collector.seed: checkpoint 7, now 8"):
        train_run(tiny(tmp_path / "run", 4, seed=8))
    config = tiny(tmp_path / "run", 4)
    other_bov = replace(config, env=replace(config.env, bov=replace(config.env.bov, match_cosine=0.6)))
    was = config.env.bov.match_cosine
    with pytest.raises(CheckpointError, match=f"env.bov.match_cosine: checkpoint {was}, now 0.6"):
        train_run(other_bov)


def test_a_checkpoint_from_before_the_render_settings_resumes(tmp_path):
    train_run(tiny(tmp_path / "run", 2))
    path = tmp_path / "run" / "checkpoint.pt"
    state = load_checkpoint(path)
    config = json.loads(state["config"])
    config["env"]["render"] = {key: config["env"]["render"][key]
                               for key in ("spp", "max_depth", "integrator", "variant", "seed")}
    save_checkpoint(path, {**state, "config": json.dumps(config)})
    train_run(tiny(tmp_path / "run", 4))
    assert load_checkpoint(path)["counters"]["frames"] == 4


def test_corrupt_checkpoint_in_run_folder_is_a_clear_cli_error(tmp_path, capsys):
    run = tmp_path / "run"
    run.mkdir()
    (run / "checkpoint.pt").write_bytes(b"not a checkpoint")
    assert main(["train", *TINY_ENV, "--frames", "2", "--out", str(run), "--no-progress"]) == 2
    assert "corrupt" in capsys.readouterr().err


def test_unknown_scene_is_a_clear_cli_error(tmp_path, capsys):
    out = str(tmp_path / "r")
    args = ["train", "--scene", "test_building", "--scene", "no_such_scene", "--envs", "2", "--frames", "2",
            "--frames-per-batch", "2", "--out", out, "--no-progress"]
    assert main(args) == 2
    assert "no_such_scene" in capsys.readouterr().err


def test_training_on_a_lattice_renders_it_first_on_the_workers(tmp_path, monkeypatch):
    import nbv.features.source
    import nbv.rl.env
    from nbv.rl.lattice import lattice_path
    from render.variant import select_variant

    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path / "cache"))  # spawned workers inherit it
    original = nbv.rl.env.build_lattice

    def cached_already(scene, make_renderer, config, features, progress=True):
        variant = select_variant(config.render.variant).variant()
        assert lattice_path(scene, config, features, variant).is_file()  # the env only reads it
        return original(scene, make_renderer, config, features, progress)

    def rendered(*args, **kwargs):
        pytest.fail("the training env built a renderer: the workers had cached the lattice")

    monkeypatch.setattr(nbv.rl.env, "build_lattice", cached_already)
    monkeypatch.setattr(nbv.features.source, "MitsubaRenderer", rendered)  # no renderer, so nothing rendered
    args = ["train", *TINY_ENV, "--lattice", "--lattice-radii", "1", "--lattice-azimuths", "4",
            "--lattice-elevations", "2", "--frames", "2", "--frames-per-batch", "2", "--init-random-frames",
            "2", "--workers", "2", "--out", str(tmp_path / "run"), "--no-progress"]
    assert main(args) == 0
    assert len(list((tmp_path / "cache" / "lattice").glob("*.pt"))) == 1
    assert load_checkpoint(tmp_path / "run" / "checkpoint.pt")["counters"]["frames"] == 2


def old_layout(record: dict) -> dict:
    """A run record as written before the reward and members groups (d439c96): the coverage weight in the
    env group, the members count in the validation group."""
    old = json.loads(json.dumps(record))
    old["env"]["coverage_reward"] = old.pop("reward")["coverage"]
    old["validation"]["members"] = old.pop("members")["count"]
    return old


def test_a_record_from_before_the_reward_group_reads_into_it():
    current = config_record(replace(tiny("run", 4), reward=RewardConfig(coverage=30.0)))
    old = old_layout(current)
    assert old["env"]["coverage_reward"] == 30.0 and "reward" not in old
    assert with_defaults(old) == current  # the groups' later fields (the flight term) take their defaults
    assert upgrade_record(old)["reward"] == {"coverage": 30.0}
    assert upgrade_record(current) == current  # today's records come back equal
    assert old["env"]["coverage_reward"] == 30.0  # the record read is left as it was


def test_shipped_records_read_into_the_reward_and_members_groups():
    from nbv.planning.registry import SHIPPED_POLICY

    old = SHIPPED_POLICY.parent / "coverage" / "policy.pt"  # the default shipped until issue 26
    config, _ = load_policy(old)
    raw = json.loads(torch.load(old, weights_only=True)["config"])
    assert raw["env"]["coverage_reward"] == 100.0 and raw["validation"]["members"] == 3  # the old layout
    assert config["reward"] == {"coverage": 100.0} and config["members"] == {"count": 3}
    assert "coverage_reward" not in config["env"] and "members" not in config["validation"]
    recorded = json.loads((old.parent / "config.json").read_text())
    assert with_defaults(recorded)["reward"] == {"coverage": 100.0, "flight": 0.0, "flight_allowance": 0.0,
                                                 "flight_excess": 0.0, "imitation": 0.0,
                                                 "teacher_horizon": 3, "teacher_discount": 0.9,
                                                 "teacher_tolerance": 0.0}
    parsed = config_from_record(TrainConfig, config)
    assert parsed.reward.coverage == 100.0 and parsed.members.count == 3


def test_a_checkpoint_from_before_the_reward_group_resumes_with_its_weight(tmp_path):
    config = replace(tiny(tmp_path / "run", 4), reward=RewardConfig(coverage=30.0))
    straight = load_checkpoint(train_run(replace(config, logger=replace(config.logger, out=tmp_path / "a"))))
    train_run(replace(config, collector=replace(config.collector, frames=2)))
    path = tmp_path / "run" / "checkpoint.pt"
    state = load_checkpoint(path)
    save_checkpoint(path, {**state, "config": json.dumps(old_layout(json.loads(state["config"])))})
    train_run(config)
    resumed = load_checkpoint(path)
    assert resumed["counters"] == straight["counters"] == {"frames": 4, "updates": 4}
    for key in straight["loss"]:  # resumed exactly, with the recorded weight
        assert torch.equal(straight["loss"][key], resumed["loss"][key]), key
    with pytest.raises(CheckpointError, match="reward.coverage: checkpoint 30.0, now 0.0"):
        train_run(replace(config, reward=RewardConfig(), collector=replace(config.collector, frames=6)))
