"""`nbv train --preset`: the validated default and the paper's Table 1, every flag still on top."""

from __future__ import annotations

import pytest

from nbv.cli import main
from nbv.cli.train import parse_train as parsed
from nbv.cli.train import split_preset
from nbv.rl.presets import TRAIN_SCENES, VALIDATION_SCENES
from scenes.presets import seed_split


def test_paper_preset_is_table_1_and_default_departs_from_it():
    paper = parsed(["--preset", "paper", "--out", "run"])
    assert paper.env.action_mode == "absolute" and not paper.env.lattice.enabled
    assert paper.optim.alpha == 0.2 and paper.optim.reward_scale == 1.0 and not paper.optim.auto_alpha
    assert paper.replay_buffer.batch_size == 8 and paper.optim.lr == 5e-4
    assert paper.env.bov.elevation_bands == 1
    default = parsed(["--out", "run"])
    assert default.env.lattice.enabled and default.env.action_mode != "absolute"
    assert default.env.scenes.scene == TRAIN_SCENES == paper.env.scenes.scene
    held_out = [s for s in TRAIN_SCENES if s in ("alpine_chalet", "imperial_temple")
                or s.startswith("random:") and seed_split(int(s[7:])) == "test"]
    assert held_out == []  # the held-out buildings are never trained on
    assert not paper.validation.enabled  # the paper keeps the last actor
    validation = default.validation.validation_scenes
    assert validation == VALIDATION_SCENES and not set(validation) & set(TRAIN_SCENES)
    assert all(seed_split(int(s[7:])) == "train" for s in validation)  # never a test building


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
    assert main(["train", "--no-actor-frames", "--out", str(tmp_path)]) == 2
    assert "needs --bov-observation" in capsys.readouterr().err
