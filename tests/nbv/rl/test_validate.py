"""Checkpoint selection on validation buildings: the score against a direct count, and training with it;
the evaluation env (the model-selection score itself: tests/nbv/planning/test_selection.py)."""

from __future__ import annotations

import csv
import json
from dataclasses import replace

import numpy as np
import pytest
import torch

from nbv.flight.record import flight_record
from nbv.recon.visibility import scene_visibility
from nbv.rl.agent import make_actor
from nbv.rl.checkpoint import load_checkpoint, load_policy
from nbv.rl.config import LatticeConfig, ValidationConfig
from nbv.rl.env import NBVEnv
from nbv.rl.rollout import policy_views
from nbv.rl.train import train_run
from nbv.rl.validate import Validator, evaluation_env_config, validation_env_config
from render.settings import RenderSettings
from render.viewpoint import viewpoint_to_c2w
from scenes.spec import SceneSet
from scripts.validated_metres import main as validated_metres
from tests.nbv.rl.test_train import tiny

SMALL_LATTICE = LatticeConfig(lattice_radii=1, lattice_azimuths=4, lattice_elevations=2)
VALIDATION = ValidationConfig(validation_scenes=("test_building",), validation_episodes=2, validation_views=3,
                              validation_points=2000)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path / "cache"))


def validated(out, frames: int, validation: ValidationConfig = VALIDATION):
    config = tiny(out, frames)
    return replace(config, env=replace(config.env, lattice=SMALL_LATTICE), validation=validation,
                   logger=replace(config.logger, checkpoint_every=2))


@pytest.mark.parametrize("exact", [False, True])
def test_score_is_the_visible_coverage_of_the_modes_views(tmp_path, cache, exact):
    config = validated(tmp_path, 2)
    validation = replace(VALIDATION, validation_exact=exact)  # exact: rendered, not the lattice's frames
    actor = make_actor(config.env.history, config.env.obs_size, config.network)
    weights = actor.state_dict()
    scores, metres = Validator(config.env, validation, config.network).score_and_metres(weights)

    env_config = validation_env_config(config.env, validation)
    assert env_config.lattice.enabled == (not exact) and env_config.scenes.scene == ("test_building",)
    env = NBVEnv(env_config)
    visibility = None
    coverages, flown = [], []
    for episode in range(2):
        env.set_seed(episode)
        views = policy_views(actor, env, 3)
        assert len(views) == 3
        visibility = visibility or scene_visibility(env.scene, env_config.camera, 2000)
        poses = [viewpoint_to_c2w(v, env.scene.center()) for v in views]
        coverages.append(visibility.coverage(poses))
        flown.append(flight_record(views[0], views[1:])["flight_m"])
    assert list(scores) == ["test_building"]
    assert scores["test_building"] == pytest.approx(100 * np.mean(coverages))
    assert 0 < scores["test_building"] <= 100 and metres == pytest.approx(np.mean(flown))
    assert (tmp_path / "cache" / "lattice").exists() == (not exact)  # exact validation needs no lattice


def test_validated_training_keeps_the_best_policy_and_trains_as_without(tmp_path, cache):
    unvalidated = replace(validated(tmp_path / "plain", 6), validation=ValidationConfig())
    plain = load_checkpoint(train_run(unvalidated))
    keeping = replace(VALIDATION, validation_keep=True)  # every validated actor kept besides the best
    ckpt = load_checkpoint(train_run(validated(tmp_path / "run", 6, keeping)))
    for key in plain["loss"]:  # validation consumes none of the training's random numbers
        assert torch.equal(plain["loss"][key], ckpt["loss"][key]), key
    assert "validation" not in plain

    with open(tmp_path / "run" / "validation.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["frames"]) for r in rows] == [2, 4, 6]
    means = [float(r["mean"]) for r in rows]
    best = int(np.argmax(means))  # the first of equal scores
    assert ckpt["validation"] == {"frames": 2 * (best + 1), "score": pytest.approx(means[best], abs=1e-3),
                                  "metres": pytest.approx(float(rows[best]["metres"]), abs=1e-3)}
    assert all(int(r["best_frames"]) <= int(r["frames"]) for r in rows)
    _, weights = load_policy(tmp_path / "run" / "policy.pt")
    policy = torch.load(tmp_path / "run" / "policy.pt", weights_only=True)
    assert policy["counters"]["frames"] == 2 * (best + 1)
    config = validated(tmp_path, 6)
    validator = Validator(config.env, VALIDATION, config.network)
    scores, metres = validator.score_and_metres(weights)
    assert scores["test_building"] == pytest.approx(means[best], abs=1e-3)
    assert float(rows[best]["metres"]) == pytest.approx(metres, abs=1e-3) and metres > 0  # flown, logged
    kept = sorted(p.name for p in (tmp_path / "run" / "validated").iterdir())  # every validated actor
    assert kept == ["policy_000002.pt", "policy_000004.pt", "policy_000006.pt"]
    for name, mean in zip(kept, means):
        assert validator.score(load_policy(tmp_path / "run" / "validated" / name)[1])["test_building"] == \
            pytest.approx(mean, abs=1e-3)
    assert not (tmp_path / "plain" / "validated").exists()
    out = tmp_path / "metres.json"  # scripts/validated_metres.py flies every kept actor again, as logged
    assert validated_metres(["--run", str(tmp_path / "run"), "--out", str(out)]) == 0
    record = json.loads(out.read_text())
    assert record["fields"] == ["lattice score %", "metres"] and sorted(record["actors"]) == \
        [f"validated/{name}" for name in kept]
    for (score, flown), row in zip((record["actors"][f"validated/{name}"] for name in kept), rows):
        assert score == pytest.approx(float(row["mean"]), abs=1e-3)
        assert flown == pytest.approx(float(row["metres"]), abs=1e-3)
    run_config = tmp_path / "run" / "config.json"  # a run validated on exact renders is rescored on them
    recorded = json.loads(run_config.read_text())
    recorded["validation"]["validation_exact"] = True
    run_config.write_text(json.dumps(recorded))
    assert validated_metres(["--run", str(tmp_path / "run"), "--out", str(out)]) == 0
    record = json.loads(out.read_text())
    exact = Validator(config.env, replace(VALIDATION, validation_exact=True), config.network)
    assert record["fields"] == ["exact score %", "metres"]
    assert record["actors"][f"validated/{kept[0]}"][0] == pytest.approx(
        exact.score(load_policy(tmp_path / "run" / "validated" / kept[0])[1])["test_building"], abs=1e-3)


def test_actors_within_the_metres_bar_are_kept_first_then_the_best_score():
    capped = ValidationConfig(validation_scenes=("test_building",), validation_max_metres=13.0)
    assert capped.rank(90.0, 12.0) > capped.rank(93.0, 16.0)  # the long flight loses whatever it covers
    assert capped.rank(91.0, 12.9) > capped.rank(90.0, 8.0)  # both within: the better score
    assert capped.rank(93.0, 17.0) > capped.rank(92.0, 16.0)  # none within: the better score
    assert capped.rank(90.0, None) > capped.rank(89.0, 5.0)  # metres unknown (an older log): within
    assert VALIDATION.rank(93.0, 16.0) > VALIDATION.rank(90.0, 12.0)  # no bar: the score alone
    with pytest.raises(ValueError, match="validation_max_metres must be >= 0"):
        ValidationConfig(validation_max_metres=-1.0)


def test_bad_validation_settings_are_refused():
    with pytest.raises(ValueError, match="validation_views must be >= 1"):
        ValidationConfig(validation_views=0)
    assert not ValidationConfig().enabled and VALIDATION.enabled


def test_the_evaluation_env_renders_exactly_the_trained_settings_on_other_scenes():
    trained = replace(tiny(None, 2).env, lattice=replace(SMALL_LATTICE, enabled=True), episode_views=3,
                      action_mode="orbit")
    scenes = SceneSet(scene=("random:6",))
    evaluation = evaluation_env_config(trained, scenes)
    assert evaluation == replace(trained, scenes=scenes, lattice=LatticeConfig())
    render = RenderSettings(spp=2)
    other = evaluation_env_config(trained, scenes, render=render, episode_views=0)
    assert other == replace(evaluation, render=render, episode_views=0)


def test_the_selection_script_runs():
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).parents[3] / "scripts" / "select_defaults.py"
    done = subprocess.run([sys.executable, str(script), "score", "--help"], capture_output=True, text=True,
                          cwd=script.parents[1], check=True)
    assert "--episodes" in done.stdout
