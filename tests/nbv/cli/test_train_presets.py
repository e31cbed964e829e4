"""`nbv train --preset`: the validated default, its forerunners and the paper's Table 1, every flag on top."""

from __future__ import annotations

import pytest

from nbv.cli import main
from nbv.cli.train import parse_train as parsed
from nbv.cli.train import split_preset
from nbv.rl.presets import TRAIN_SCENES, VALIDATION_SCENES
from scenes.family_splits import held_out


def test_paper_preset_is_table_1_and_default_departs_from_it():
    paper = parsed(["--preset", "paper", "--out", "run"])
    assert paper.env.action_mode == "absolute" and not paper.env.lattice.enabled
    assert paper.optim.alpha == 0.2 and paper.optim.reward_scale == 1.0 and not paper.optim.auto_alpha
    assert paper.replay_buffer.batch_size == 8 and paper.optim.lr == 5e-4
    assert paper.env.bov.elevation_bands == 1
    assert paper.env.scenes.scene == TRAIN_SCENES
    assert not paper.validation.enabled  # the paper keeps the last actor
    for name in ("default", "coverage", "looks"):
        config = parsed(["--preset", name, "--out", "run"])
        assert config.env.lattice.enabled and config.env.action_mode != "absolute", name
        scenes, validation = config.env.scenes.scene, config.validation.validation_scenes
        assert set(TRAIN_SCENES) <= set(scenes) and not set(validation) & set(scenes), name
        assert [s for s in scenes + validation if held_out(s)] == [], name  # held-out buildings never used
        assert [s for s in validation if s.startswith("random:")] == list(VALIDATION_SCENES), name


def test_default_is_the_looks_preset_with_the_chosen_additions():
    default, looks = parsed(["--out", "run"]), parsed(["--preset", "looks", "--out", "run"])
    assert default.env.bov_observation and default.env.look_map and not looks.env.look_map
    assert (default.env.action_mode, default.env.relative_step) == ("orbit", 0.16666667)
    assert (default.reward.coverage, default.reward.flight, default.reward.imitation) == (100.0, 0.2, 1000.0)
    assert len(default.env.scenes.scene) == 28 and default.members.count == default.executor.workers == 2
    assert set(looks.env.scenes.scene) < set(default.env.scenes.scene)
    assert default.validation.validation_scenes == looks.validation.validation_scenes
    assert default.validation.validation_exact and default.validation.validation_keep  # exact renders
    assert default.validation.validation_max_metres == 13.1 and looks.validation.validation_max_metres == 0
    coverage = parsed(["--preset", "coverage", "--out", "run"])
    assert coverage.env.scenes.scene == TRAIN_SCENES and not coverage.env.bov_observation
    assert (coverage.env.action_mode, coverage.reward.flight, coverage.members.count) == ("relative", 0.0, 3)


def test_flags_override_the_preset_and_scenes_replace_its_list():
    config = parsed(["--preset=paper", "--action-mode", "orbit", "--scene", "test_building", "--out", "run"])
    assert config.env.action_mode == "orbit" and config.env.scenes.scene == ("test_building",)
    two = parsed(["--scene", "a", "--scene", "b", "--out", "run"])
    assert two.env.scenes.scene == ("a", "b")


def test_unknown_preset_is_one_line(tmp_path, capsys):
    assert main(["train", "--preset", "fast", "--out", str(tmp_path)]) == 2
    assert "unknown preset 'fast'; presets: default, paper" in capsys.readouterr().err
    with pytest.raises(ValueError, match="unknown preset"):
        split_preset(["--preset", "best"])


def test_an_actor_without_frames_is_refused_without_the_bov_vector(tmp_path, capsys):
    assert not parsed(["--preset", "looks", "--no-actor-frames", "--out", "run"]).network.actor_frames
    assert main(["train", "--preset", "coverage", "--no-actor-frames", "--out", str(tmp_path)]) == 2
    assert "needs --bov-observation" in capsys.readouterr().err
