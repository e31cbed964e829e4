"""A trained actor flying an episode: the viewpoints it chooses from the env's start view.

Shared by `nbv plan --planner policy` (`nbv.planning.policy.PolicyPlanner`) and the checkpoint
selection of `nbv train` (`nbv.rl.validate`), so both score the same behaviour.
"""

from __future__ import annotations

import math

import torch
from torchrl.envs.utils import ExplorationType, set_exploration_type
from torchrl.modules import ProbabilisticActor

from nbv.rl.env import NBVEnv
from render.viewpoint import Viewpoint


def policy_views(actor: ProbabilisticActor, env: NBVEnv, views: int | None, sample: bool = False,
                 seed: int = 0) -> list[Viewpoint]:
    """Reset `env` and act until the episode ends (one pass or the step cap), or for exactly `views` views:
    on the action distribution's mode, or on draws seeded by `seed` (the global torch state is kept)."""
    td = env.reset()
    chosen = [env.viewpoint]
    exploration = ExplorationType.RANDOM if sample else ExplorationType.DETERMINISTIC
    with torch.no_grad(), set_exploration_type(exploration), torch.random.fork_rng():
        torch.manual_seed(seed)
        while len(chosen) < (math.inf if views is None else views):
            td = env.step(actor(td))
            chosen.append(env.viewpoint)
            done = bool(td["next", "done"])
            td = td["next"]
            if views is None and done:
                break
    return chosen
