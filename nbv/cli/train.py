"""`nbv train --scene SCENE [--scene ...] --frames N --envs K --out RUN`: SAC on the NBV env."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.rl.config import TrainConfig
from nbv.rl.train import train


def main(args: Sequence[str], prog: str) -> int:
    """Parse `TrainConfig`, train (or resume) into the run folder, print the checkpoint path."""
    print(train(parse(TrainConfig, args, prog)))
    return 0
