"""`nbv train [--preset default|paper] [--scene SCENE ...] --out RUN`: SAC on the NBV env."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import tyro

from nbv.cli.parse import parse
from nbv.rl.command import train_command
from nbv.rl.config import TrainConfig
from nbv.rl.presets import PRESETS
from scenes.spec import SceneSet


def split_preset(args: Sequence[str]) -> tuple[str, list[str]]:
    """The `--preset NAME` of the arguments (default: `default`) and the other arguments."""
    rest, name, args = [], "default", list(args)
    while args:
        arg = args.pop(0)
        if arg == "--preset" and args:
            name = args.pop(0)
        elif arg.startswith("--preset="):
            name = arg.partition("=")[2]
        else:
            rest.append(arg)
    if name not in PRESETS:
        raise ValueError(f"unknown preset {name!r}; presets: {', '.join(PRESETS)}")
    return name, rest


def parse_train(args: Sequence[str], prog: str = "nbv train") -> TrainConfig:
    """`TrainConfig` from the command line: the `--preset`'s values with every given flag on top."""
    name, rest = split_preset(args)
    preset = PRESETS[name]()
    if any(arg == "--scene" or arg.startswith("--scene=") for arg in rest):
        # --scene appends: given scenes replace the preset's instead of joining them
        preset = replace(preset, env=replace(preset.env, scenes=SceneSet(scene=tyro.MISSING)))
    description = (f"Soft Actor-Critic on the NBV env, preset {name!r} (--preset {{{','.join(PRESETS)}}}: "
                   "the validated default, the paper's Table 1, or the issue-26 candidate with the Bag of "
                   "Views observation and the family buildings; every flag overrides the preset).")
    return parse(TrainConfig, rest, prog, default=preset, description=description)


def main(args: Sequence[str], prog: str) -> int:
    """Parse the config, train (or resume) into the run folder, print the checkpoint path."""
    print(train_command(parse_train(args, prog)))
    return 0
