"""Every sub-command builds its parser (no two nested configs share a flag name) and documents its flags."""

from __future__ import annotations

import re

import pytest

from nbv.cli import COMMANDS, main

OLD_SPELLINGS = ("--bov-ranges", "--bov-words", "--bov-memory", "--features", "--n-points",
                 "--match-tolerance-px")
"""The second flags six knobs answered to until issue 25: each knob now has one name."""


@pytest.mark.parametrize("name", [n for n in COMMANDS if n != "scene"] + ["scene export", "scene gallery"])
def test_help_builds_and_exits_0(name, capsys):
    assert main([*name.split(), "--help"]) == 0
    assert "usage: nbv " + name in capsys.readouterr().out


@pytest.mark.parametrize("name, flags", [
    ("scan", ["hemisphere", "circle", "--width", "--spp", "--up-axis", "--seed", "--variant", "--denoiser",
              "--pixel-filter",
              "--resolution-scale", "--texture-scale", "--motion-blur-m", "--motion-blur-frames",
              "--sky-model", "--light-mode", "--sun-elevation-deg", "--sun-azimuth-deg", "--turbidity",
              "--exposure-stops", "--shot-noise", "--read-noise", "--jpeg-quality"]),
    ("plan", ["--planner", "--views", "--match-cosine", "--up-axis", "--focal-mm", "--metric-points",
              "infogain", "oracle", "--candidates", "--grid-resolution", "--gain-ray-stride",
              "--denoiser", "--jpeg-quality", "--sky-model"]),
    ("train", ["--scene", "--frames", "--ranges", "--feature-backend", "--match-cosine", "--up-axis",
               "--denoiser", "--jpeg-quality", "--light-mode"]),
    ("demo", ["--width", "--ranges", "--words", "--up-axis", "--voxel-size-m", "--metric-points"]),
    ("tables", ["--scenes", "--ranges", "--words", "--up-axis", "--match-cosine"]),
    ("refine", ["--ranges", "--words", "--feature-backend", "--max-features", "--contrast-threshold",
                "--double-image", "--match-cosine", "--memory-cap"]),
    ("evaluate", ["--gt", "--up-axis", "--reference", "--metric-points", "--seed"]),
    ("ablate", ["--tolerance-px", "--ranges", "--feature-backend", "--metric-points"]),
])
def test_one_knob_one_flag_name(name, flags, capsys):
    main([name, "--help"])
    text = capsys.readouterr().out
    missing = [flag for flag in flags if flag not in text]
    assert missing == []
    offered = set(re.findall(r"--[a-z][a-z0-9-]*", text))
    assert offered & set(OLD_SPELLINGS) == set()  # each knob answers to its one name only


@pytest.mark.parametrize("args", [
    ["refine", "DATASET", "--out", "OUT", "--bov-ranges", "2"],
    ["refine-sweep", "DATASET", "--out", "OUT", "--bov-words", "5"],
    ["refine", "DATASET", "--out", "OUT", "--bov-memory", "64"],
    ["refine", "DATASET", "--out", "OUT", "--features", "opencv"],
    ["evaluate", "MESH", "--gt", "test_building", "--out", "OUT", "--n-points", "100"],
    ["ablate", "--match-tolerance-px", "2"],
])
def test_an_old_second_spelling_is_refused(args, capsys):
    assert main(args) == 2
    assert f"Unrecognized options: {args[-2]}" in capsys.readouterr().err
