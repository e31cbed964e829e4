"""The running episode's return (`episode_reward`) of the training env, continued across a resume.

TorchRL's `RewardSum` zeroes the return at every reset, and a resumed run's first reset is the one that
continues the restored episode (`NBVEnv.restore`), so its return restarted at 0: the logged
`episode_return` and the replay buffer's `episode_reward` then differed from a run that went through.
`EpisodeReturn` keeps the return the env answers that reset with (the env sums its episode's rewards
in float32, as `RewardSum` does, and checkpoints the sum with the rest of its state).
"""

from __future__ import annotations

from tensordict import TensorDictBase
from torchrl.envs import RewardSum

RETURN_KEY = "episode_reward"
"""`RewardSum`'s output key: the return so far of the episode in progress."""


class EpisodeReturn(RewardSum):
    """`RewardSum` over the reward, except that a reset answered with a return (a restored episode
    continuing) keeps that return instead of zeroing it."""

    def _reset(self, tensordict: TensorDictBase, tensordict_reset: TensorDictBase) -> TensorDictBase:
        resumed = tensordict_reset.get(RETURN_KEY, None)
        tensordict_reset = super()._reset(tensordict, tensordict_reset)
        if resumed is not None:
            tensordict_reset.set(RETURN_KEY, resumed)
        return tensordict_reset
