"""The NBV environment behind Gymnasium's API (for libraries such as Stable-Baselines3; docs/rl.md).

`NBVGymEnv` wraps one in-process `NBVEnv`: the same state, action, reward,
termination and truncation, as NumPy arrays and Gymnasium's 5-tuples.
Seeding goes through `reset(seed=...)`: the seed becomes the wrapped env's
seed (start viewpoints, render noise, Bag of Views), so a seeded episode is
reproducible; an unseeded reset continues the current random stream, and the
first reset without any seed draws one from Gymnasium's `np_random`.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
import torch
from gymnasium import spaces
from tensordict import TensorDict

from nbv.rl.config import EnvConfig
from nbv.rl.env import NBVEnv


class NBVGymEnv(gymnasium.Env):
    """Next-best-view planning as a `gymnasium.Env` (Dict observation, Box action).

    Observation: `pixels`, uint8 (history, obs_size, obs_size), the last grayscale
    frames; `viewpoints`, float32 (history, 3) in [-1, 1], the last normalised
    viewpoints. Action: float32 (3,) in [-1, 1] (`EnvConfig.action_mode`).
    Info: `viewpoint`, the current (R, azimuth, elevation) in metres and radians.

    Args:
        config: scenes, camera, allowed ranges, episode and Bag of Views settings.
    """

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(self, config: EnvConfig) -> None:
        self.config = config
        self.env = NBVEnv(config)
        tau, side = config.history, config.obs_size
        self.observation_space = spaces.Dict({
            "pixels": spaces.Box(0, 255, shape=(tau, side, side), dtype=np.uint8),
            "viewpoints": spaces.Box(-1.0, 1.0, shape=(tau, 3), dtype=np.float32),
        })
        self.action_space = spaces.Box(-1.0, 1.0, shape=(3,), dtype=np.float32)
        self._seeded = False

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start an episode; `seed` reseeds the wrapped env (and Gymnasium's `np_random`)."""
        super().reset(seed=seed)
        if seed is not None or not self._seeded:
            self.env.set_seed(int(seed) if seed is not None else int(self.np_random.integers(2**31)))
            self._seeded = True
        return self._observation(self.env.reset()), self._info()

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """Fly to the viewpoint `action` asks for: (observation, reward, terminated, truncated, info)."""
        action = torch.as_tensor(np.asarray(action, dtype=np.float32))
        out = self.env.step(TensorDict({"action": action}, batch_size=[]))["next"]
        return (self._observation(out), float(out["reward"].item()), bool(out["terminated"].item()),
                bool(out["truncated"].item()), self._info())

    def close(self) -> None:
        """Release the wrapped env."""
        if not self.env.is_closed:
            self.env.close()

    def _observation(self, td: TensorDict) -> dict[str, np.ndarray]:
        return {"pixels": td["pixels"].numpy().copy(), "viewpoints": td["viewpoints"].numpy().copy()}

    def _info(self) -> dict[str, Any]:
        return {"viewpoint": self.env.viewpoint.as_array()}
