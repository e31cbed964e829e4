"""`nbv train --scene SCENE [--scene ...] --frames N --envs K --out RUN`: SAC on the NBV env."""

from __future__ import annotations

import argparse

from nbv.agent import NetworkConfig
from nbv.cli.config_args import add_config_arguments, config_from_args
from nbv.env import EnvConfig
from nbv.train import train
from nbv.train_builders import CollectorConfig, LoggerConfig, OptimConfig, ReplayBufferConfig, TrainConfig

GROUPS = {"env": EnvConfig, "collector": CollectorConfig, "replay_buffer": ReplayBufferConfig,
          "optim": OptimConfig, "network": NetworkConfig, "logger": LoggerConfig}
"""`TrainConfig` field -> its config class; each becomes one group of options in --help."""


def config_from_namespace(args: argparse.Namespace) -> TrainConfig:
    """The `TrainConfig` of parsed `nbv train` arguments."""
    return TrainConfig(**{name: config_from_args(cls, args) for name, cls in GROUPS.items()})


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `train` sub-command."""
    p = subparsers.add_parser("train", help="train the SAC next-best-view policy (resumes a run folder)")
    for name, cls in GROUPS.items():
        add_config_arguments(p.add_argument_group(name, (cls.__doc__ or "").strip()), cls)
    p.set_defaults(func=lambda args: print(train(config_from_namespace(args))))
