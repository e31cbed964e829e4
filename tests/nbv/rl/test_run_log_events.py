"""TensorBoard after a resume (issue 28): the steps a killed run logged past its checkpoint are purged, so
the event stream read back holds each step once, with the resumed run's values."""

from __future__ import annotations

import torch
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator
from tensordict import TensorDict

from nbv.rl.config import EnvConfig, LoggerConfig, TrainConfig
from nbv.rl.train import RunLog
from scenes.spec import SceneSet


def batch(reward: float, frames: int = 2) -> TensorDict:
    """A collected batch of `frames` steps, each with `reward`, no episode ending."""
    return TensorDict({("next", "reward"): torch.full((frames, 1), reward),
                       ("next", "done"): torch.zeros(frames, 1, dtype=torch.bool),
                       ("next", "episode_reward"): torch.zeros(frames, 1)}, [frames])


def logged(run, config: TrainConfig, start: int, rewards: list[float]) -> None:
    """A run from the checkpoint at `start` frames logging one batch of 2 frames per reward, then dying."""
    with RunLog(run, config, start) as log:
        for i, reward in enumerate(rewards):
            log.log_batch(batch(reward), start + 2 * (i + 1), i, {}, 0.0, 0.0)


def test_resumed_run_logs_each_step_once_with_its_own_values(tmp_path):
    config = TrainConfig(env=EnvConfig(scenes=SceneSet(scene=("test_building",))),
                         logger=LoggerConfig(out=tmp_path, progress=False))
    logged(tmp_path, config, 0, [1.0, 2.0, 3.0])  # checkpoint at 4 frames, killed after logging 6
    logged(tmp_path, config, 4, [30.0, 40.0])  # resumed at 4: logs 6 again, then 8
    events = EventAccumulator(str(tmp_path / "tensorboard"))
    events.Reload()
    rewards = [(e.step, e.value) for e in events.Scalars("train/reward_mean")]
    assert rewards == [(2, 1.0), (4, 2.0), (6, 30.0), (8, 40.0)]
