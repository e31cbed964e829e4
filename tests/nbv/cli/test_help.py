"""Every sub-command builds its parser (no two nested configs share a flag name) and documents its flags."""

from __future__ import annotations

import pytest

from nbv.cli import COMMANDS, main


@pytest.mark.parametrize("name", [n for n in COMMANDS if n != "scene"] + ["scene export", "scene gallery"])
def test_help_builds_and_exits_0(name, capsys):
    assert main([*name.split(), "--help"]) == 0
    assert "usage: nbv " + name in capsys.readouterr().out


@pytest.mark.parametrize("name, flags", [
    ("scan", ["--width", "--spp", "--up-axis", "--seed", "--variant", "--denoiser", "--pixel-filter",
              "--resolution-scale", "--texture-scale", "--motion-blur-m", "--motion-blur-frames",
              "--sky-model", "--light-mode", "--sun-elevation-deg", "--sun-azimuth-deg", "--turbidity",
              "--exposure-stops", "--shot-noise", "--read-noise", "--jpeg-quality"]),
    ("plan", ["--planner", "--views", "--match-cosine", "--up-axis", "--focal-mm", "--metric-points",
              "infogain", "oracle", "--candidates", "--grid-resolution", "--gain-ray-stride",
              "--denoiser", "--jpeg-quality", "--sky-model"]),
    ("train", ["--scene", "--frames", "--bov-ranges", "--feature-backend", "--match-cosine", "--up-axis",
               "--denoiser", "--jpeg-quality", "--light-mode"]),
    ("demo", ["--width", "--ranges", "--words", "--up-axis", "--voxel-size-m", "--metric-points"]),
    ("tables", ["--scenes", "--ranges", "--words", "--up-axis", "--match-cosine"]),
    ("refine", ["--ranges", "--words", "--features", "--match-cosine", "--memory-cap"]),
    ("evaluate", ["--gt", "--up-axis", "--reference", "--n-points", "--seed"]),
])
def test_one_knob_one_flag_name(name, flags, capsys):
    main([name, "--help"])
    text = capsys.readouterr().out
    missing = [flag for flag in flags if flag not in text]
    assert missing == []
