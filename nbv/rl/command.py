"""`nbv train`'s command: the scenes' view lattices rendered first, then one run or several members.

The loop of one run is `nbv.rl.train.train_run`; the members (`nbv.rl.members`) run that loop once per
seed. This module decides between them, so neither the loop nor the members import back.
"""

from __future__ import annotations

from pathlib import Path

from common.threads import set_torch_threads
from nbv.fanout.executor import run_tasks
from nbv.rl.config import TrainConfig
from nbv.rl.lattice import lattice_tasks
from nbv.rl.members import train_members
from nbv.rl.train import train_run
from nbv.rl.validate import validation_env_config


def train_command(config: TrainConfig) -> Path:
    """`nbv train`: render the lattices not cached yet, then train (or resume) into `config.logger.out`;
    return the checkpoint path (with `--members K`, the kept member's: `nbv.rl.members`)."""
    if config.members.count == 1:
        set_torch_threads(config.collector.threads)  # an in-process lattice renders as the run would
    render_lattices(config)
    return train_members(config) if config.members.count > 1 else train_run(config)


def render_lattices(config: TrainConfig) -> None:
    """Render the training (--lattice) and validation buildings' view lattices not cached yet, side by side
    where the executor says, so envs and members then read the cache instead of each rendering them."""
    tasks = lattice_tasks(config.env) if config.env.lattice.enabled else []
    if config.validation.enabled and not config.validation.validation_exact:
        tasks += lattice_tasks(validation_env_config(config.env, config.validation))
    run_tasks(tasks, config.executor)
