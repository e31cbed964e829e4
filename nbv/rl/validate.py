"""Checkpoint selection on validation buildings: the policy's mode scored by what its views see.

Training return measures the Bag of Views reward, not the reconstruction, and it varies with the
start views and buildings of the episodes that happen to be sampled; the last actor of a run is not
its best (docs/rl.md §11). So `nbv train` with validation buildings scores the actor at every
checkpoint: from the same seeded start views on each validation building, its mode flies a fixed
number of views on the building's view lattice (the training cache, so no view is rendered again) or,
with `validation_exact`, on exact renders as evaluation flies them, and the score is the share of the
true surface those views see (`nbv.recon.visibility`, a ray-cast depth test at each view's exact pose).
`policy.pt` keeps the best-scoring actor (within the metres bar first, `ValidationConfig.rank`). On the
lattice the policy sees the nearest nodes' frames as in training, which moves its actions: evaluation
(`nbv plan`, `nbv online`) renders exact viewpoints, as exact validation does.

`evaluation_env_config` is the one recipe of an env that evaluates a trained policy's settings (exact
renders, no lattice; no training-only reward term, which lives in `TrainConfig.reward`, not in the env):
planning with a policy and the model selection across runs (`nbv.planning.selection`) use it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import torch

from nbv.flight.record import flight_record
from nbv.recon.visibility import SurfaceVisibility, scene_visibility
from nbv.rl.agent import make_actor
from nbv.rl.bov_observation import bov_observation_size
from nbv.rl.config import EnvConfig, LatticeConfig, NetworkConfig, ValidationConfig
from nbv.rl.env import NBVEnv
from nbv.rl.rollout import policy_views
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.spec import SceneSet


def validation_env_config(env: EnvConfig, validation: ValidationConfig) -> EnvConfig:
    """The training env on the validation buildings, on view lattices (the training lattice settings), or
    on exact renders with `validation_exact`."""
    scenes = SceneSet(scene=validation.validation_scenes, up_axis=env.scenes.up_axis)
    return replace(env, scenes=scenes, lattice=replace(env.lattice, enabled=not validation.validation_exact))


def evaluation_env_config(trained: EnvConfig, scenes: SceneSet, render: RenderSettings | None = None,
                          episode_views: int | None = None) -> EnvConfig:
    """The env that evaluates a trained env's settings on `scenes`: exact renders (no lattice), the
    trained state, actions and Bag of Views; `render` and `episode_views` replace the trained ones when
    given. It has no training-only reward term: those are `TrainConfig.reward`, never an env setting."""
    changes = {"render": render, "episode_views": episode_views}
    return replace(trained, scenes=scenes, lattice=LatticeConfig(),
                   **{key: value for key, value in changes.items() if value is not None})


def mean_score(scores: dict[str, float]) -> float:
    """An actor's validation score: the mean over the buildings of `Validator.score`'s coverages (%)."""
    return float(sum(scores.values()) / len(scores))


class Validator:
    """Scores actor weights on the validation buildings (mean visible coverage, %, per building), on their
    view lattices or on exact renders (`ValidationConfig.validation_exact`).

    Args:
        env: the training env config (its camera, lattice, action mode and Bag of Views are used).
        validation: buildings, episodes and views.
        network: the actor's sizes.
    """

    def __init__(self, env: EnvConfig, validation: ValidationConfig, network: NetworkConfig) -> None:
        self.validation = validation
        self.config = validation_env_config(env, validation)
        with torch.random.fork_rng():  # its initial weights are overwritten: draw none of training's numbers
            self.actor = make_actor(env.history, env.obs_size, network, bov_observation_size(env))
        self.actor.eval()
        self._envs: dict[str, NBVEnv] = {}
        self._visibility: dict[str, SurfaceVisibility] = {}
        self._seen: dict[tuple[str, bytes], np.ndarray] = {}

    def score(self, weights: dict[str, torch.Tensor]) -> dict[str, float]:
        """Visible coverage (%) of each validation building by the actor's mode, mean over the episodes."""
        return self.score_and_metres(weights)[0]

    def score_and_metres(self, weights: dict[str, torch.Tensor]) -> tuple[dict[str, float], float]:
        """`score`, and the metres the mode flies per episode along the viewing shell from its start view
        (`nbv.flight.record.flight_record`), mean over every building and episode."""
        self.actor.load_state_dict(weights)
        scores, metres = {}, []
        for spec in self.config.scenes.specs():
            env = self._env(spec.scene)
            runs = []
            for episode in range(self.validation.validation_episodes):
                env.set_seed(episode)
                views = policy_views(self.actor, env, self.validation.validation_views)
                runs.append(self._coverage(spec.scene, env, views))
                metres.append(flight_record(views[0], views[1:])["flight_m"])
            scores[spec.scene] = 100.0 * float(np.mean(runs))
        return scores, float(np.mean(metres))

    def _env(self, scene: str) -> NBVEnv:
        if scene not in self._envs:
            config = replace(self.config, scenes=replace(self.config.scenes, scene=(scene,)))
            self._envs[scene] = NBVEnv(config)
        return self._envs[scene]

    def _coverage(self, scene: str, env: NBVEnv, views: list[Viewpoint]) -> float:
        """The share of the building's surface samples seen by the views (memoised: a converged mode
        flies the same views at many checkpoints)."""
        if scene not in self._visibility:
            self._visibility[scene] = scene_visibility(env.scene, self.config.camera,
                                                       self.validation.validation_points)
        visibility = self._visibility[scene]
        seen = np.zeros(len(visibility.samples), dtype=bool)
        for view in views:
            key = (scene, view.as_array().tobytes())
            if key not in self._seen:
                self._seen[key] = visibility.seen(viewpoint_to_c2w(view, env.scene.center()))
            seen |= self._seen[key]
        return float(seen.mean())
