"""`nbv plot-training [LABEL=]RUN [...] --out curves.png`: overlay the learning curves of `nbv train` runs."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.viz.figures import PlotTrainingConfig, plot_training


def main(args: Sequence[str], prog: str) -> int:
    """Parse `PlotTrainingConfig`, draw reward per step, episode return and steps per episode."""
    print(plot_training(parse(PlotTrainingConfig, args, prog)))
    return 0
