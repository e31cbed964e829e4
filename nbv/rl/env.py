"""The online next-best-view problem as a TorchRL environment (paper Sec. IV; docs/rl.md).

State: the last `history` (tau = 5) grayscale frames, downsampled to `obs_size` x `obs_size` (uint8, key
`pixels`), and the last `history` viewpoints (R, azimuth, elevation), each normalised to [-1, 1] over its
allowed range (key `viewpoints`; zeros with `pose_observation` off). At reset both histories hold copies of
the first view. With `bov_observation`, the `bov` vector (`nbv.rl.bov_observation`); with the diagnostic
`privileged_unseen`, the env tracks the episode's seen surface samples to end it in their unseen map.

Action: three values in [-1, 1]. In the paper's `absolute` mode they are the next viewpoint itself,
rescaled to the allowed ranges of R, azimuth and elevation ("rescaled to conform to the specified ranges",
Sec. IV); in the `relative` mode they are a step from the current viewpoint, at most `relative_step` of
each range, clipped to the ranges; in the `orbit` mode the azimuth is such a step and R and elevation are
absolute; in the `forward` mode (beyond the paper) R and elevation are absolute and the azimuth always
advances, by half to all of `relative_step` of a turn, as a pilot's orbit does (no hovering, no turning
back). Orbit exists because absolute azimuth is a circular target that a tanh output cannot follow across
0 = 2 pi (moving on by 45 degrees from 350 needs an action jump from +1 to -1), and it keeps R and
elevation free of the drift of relative steps (measured, with unscaled rewards: a relative policy flew
every view at R = 1.5 m, 5 degrees up; on the held-out chalet those close, low views happened to cover the
surface best, see paper_results/planners).

Reward: the Bag of Views reward of the new view (vocabulary change - 1, docs/bov.md), from the config's `bov`
(its match cosine included; with `elevation_bands` E > 1 each azimuth range is split into E bands over the
allowed elevations, beyond the paper). The BoV is emptied at each reset and learns the episode's first view
without reward. With training-only `reward_terms` (`RewardConfig`, given by the training builders alone) of
coverage weight W > 0 (beyond the paper: it reads the true mesh) the reward adds W x the share of the target's
surface samples (`nbv.recon.visibility`) that the new view is the episode's first to see; on a lattice that is
the node's view, as the frame is. With an imitation weight > 0 (`RewardConfig.imitation`) every state also
holds the privileged teacher's action (`expert_action`, `nbv.rl.expert`), and with a `teacher_tolerance` its
near-ties (`expert_near_best`), which the actor never reads: the SAC update pulls the actor's mode towards
them.

Termination: one pass around the target, i.e. the net azimuth travelled (each step's change wrapped to
(-pi, pi]) reaches 2 pi in either direction; or, with `episode_views` N > 0 (a fixed view budget, beyond the
paper), the N-th view, and passes do not end it. Truncation: `max_steps` steps.

Lattice (training): the env's viewpoint stays the exact one the actions lead to (steps accumulate, and the
state records it); only the frame and the descriptors come from the nearest lattice node. Snapping the
viewpoint itself kept relative steps smaller than half a node spacing from ever moving the camera (R never
changed, elevation only at |action| > 0.8), so policies trained that way flew one ring at their start
elevation.

Rendering: through a view source (`nbv.features.source.ViewSource`, the one the planners and the validator use
too): one renderer per scene (loaded with the scene set's up axis), created lazily on the first reset, in the
process that steps the env, so `ParallelEnv`'s spawned workers each choose their own Mitsuba variant; view k
is rendered with the config's render settings' `view_seed(k)` under the env's seed. `render_depth` gives the
z-depth a depth camera returns at a view, timed apart from the RGB renders. The constructor takes only
picklable settings (or a view source to share). Before the first view is rendered the process's torch threads
follow the thread policy (`common.threads.apply_thread_policy`: 1 unless the process chose otherwise), since
the renderer and Kornia SIFT share the cores with everything else.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
import torch
from tensordict import TensorDict, TensorDictBase
from torchrl.data import Bounded, Categorical, Composite, Unbounded
from torchrl.envs import EnvBase

from common.threads import apply_thread_policy
from nbv.bov.bag import BagOfViews
from nbv.features.sift import FeatureConfig
from nbv.features.source import ViewSource
from nbv.flight.path import shell_path
from nbv.recon.visibility import SurfaceVisibility, scene_visibility
from nbv.rl.bov_observation import BOV_KEY, bov_observation_size, bov_vector, novelty_of
from nbv.rl.config import EnvConfig, RewardConfig
from nbv.rl.episode_return import RETURN_KEY
from nbv.rl.expert import (
    CANDIDATES,
    EXPERT_KEY,
    EXPERT_SET_KEY,
    best_action,
    expert_scores,
    label_keys,
    near_best,
)
from nbv.rl.flight_cost import flight_cost
from nbv.rl.lattice import ViewLattice, build_lattice
from nbv.rl.look_map import look_of
from nbv.rl.unseen_map import sample_bins, unseen_map
from render.viewpoint import TWO_PI, Viewpoint, draw_viewpoint, viewpoint_to_c2w
from scenes.model import Scene
from scenes.spec import SceneSpec


def check_action(action: Any) -> np.ndarray:
    """The action as float64 (3,), or a ValueError if it is NaN, infinite or outside [-1, 1]."""
    a = np.asarray(action.detach().cpu() if isinstance(action, torch.Tensor) else action, dtype=np.float64)
    if a.shape != (3,):
        raise ValueError(f"an NBV action has 3 values (R, azimuth, elevation), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"NBV action contains NaN or infinite values: {a.tolist()}")
    if np.any(np.abs(a) > 1.0 + 1e-6):
        raise ValueError(f"NBV action must lie in [-1, 1], got {a.tolist()}")
    return np.clip(a, -1.0, 1.0)


def normalise_viewpoint(view: Viewpoint, config: EnvConfig) -> np.ndarray:
    """(R, azimuth, elevation) mapped to [-1, 1] over the allowed ranges (the inverse of `absolute`)."""
    return 2.0 * (view.as_array() - config.low) / np.maximum(config.high - config.low, 1e-12) - 1.0


def action_to_viewpoint(action: Any, current: Viewpoint, config: EnvConfig) -> Viewpoint:
    """The next viewpoint an action asks for, under the config's action mode."""
    a = check_action(action)
    low, high = config.low, config.high
    absolute = low + (a + 1.0) / 2.0 * (high - low)
    step = current.as_array() + a * config.relative_step * (high - low)
    if config.action_mode == "absolute":
        r, az, el = absolute
    elif config.action_mode == "orbit":
        r, az, el = absolute[0], step[1], absolute[2]
    elif config.action_mode == "forward":
        advance = (a[1] + 3.0) / 4.0 * config.relative_step * TWO_PI
        r, az, el = absolute[0], current.azimuth + advance, absolute[2]
    else:
        r, az, el = step
        r, el = np.clip(r, low[0], high[0]), np.clip(el, low[2], high[2])
    return Viewpoint(float(r), float(az) % TWO_PI, float(el))


def wrap_angle(angle: float) -> float:
    """An angle difference wrapped to (-pi, pi]."""
    wrapped = math.remainder(angle, TWO_PI)
    return math.pi if wrapped == -math.pi else wrapped


def check_source(source: ViewSource, config: EnvConfig, features: FeatureConfig) -> None:
    """Refuse a shared view source whose camera, render settings, features or frame size are not the env's."""
    ours = (config.camera, config.render, features, config.obs_size)
    render = replace(source.render, seed=config.render.seed)  # the env reseeds it
    theirs = (source.camera, render, source.features, source.frame_size)
    for name, mine, its in zip(("camera", "render", "features", "obs_size"), ours, theirs):
        if mine != its:
            raise ValueError(f"the view source's {name} is {its!r}, the env's {mine!r}")


class NBVEnv(EnvBase):
    """Next-best-view planning around one target at a time, rewarded by the Bag of Views.

    Args:
        config: scenes, camera, allowed ranges, episode and Bag of Views settings.
        worker: index of this env among parallel workers; it offsets the scene order.
        seed: seed of the start viewpoints, the render noise and the BoV clustering.
        reward_terms: training-only reward terms (`TrainConfig.reward`, from `nbv.rl.builders`); by default
            none, so an env built from an `EnvConfig` alone never reads the true mesh.
        source: the view source to render with (shared with a planner); default: a new one on the
            config's camera, render, feature and frame settings.
        blank_images: replace every captured image by a blank one (a black frame, no descriptors): an
            evaluation-time test of how much the policy's choices depend on what it sees.

    Example:
        >>> from render.camera import UAVCamera
        >>> from scenes.spec import SceneSet
        >>> scenes = SceneSet(scene=("test_building",))
        >>> env = NBVEnv(EnvConfig(scenes=scenes, camera=UAVCamera(64, 48), obs_size=32))
        >>> td = env.rollout(3)
    """

    def __init__(self, config: EnvConfig, worker: int = 0, seed: int = 0,
                 reward_terms: RewardConfig = RewardConfig(), source: ViewSource | None = None,
                 blank_images: bool = False) -> None:
        super().__init__(device="cpu", batch_size=torch.Size([]))
        self.config = config
        self.reward_terms = reward_terms
        self.worker = worker
        self.blank_images = blank_images
        self._tracks_seen = bool(reward_terms.coverage or reward_terms.imitation or config.privileged_unseen)
        tau, side = config.history, config.obs_size
        extra = {BOV_KEY: Unbounded(shape=(bov_observation_size(config),), dtype=torch.float32)
                 } if config.bov_observation else {}
        labels = {EXPERT_KEY: Bounded(-1.0, 1.0, shape=(3,), dtype=torch.float32),
                  EXPERT_SET_KEY: Categorical(2, shape=(len(CANDIDATES),), dtype=torch.bool)}
        extra.update({key: labels[key] for key in label_keys(reward_terms)})
        self.observation_spec = Composite(
            pixels=Bounded(0, 255, shape=(tau, side, side), dtype=torch.uint8),
            viewpoints=Bounded(-1.0, 1.0, shape=(tau, 3), dtype=torch.float32),
            **extra,
        )
        self.action_spec = Bounded(-1.0, 1.0, shape=(3,), dtype=torch.float32)
        self.reward_spec = Unbounded(shape=(1,), dtype=torch.float32)
        self.done_spec = Composite({key: Categorical(2, shape=(1,), dtype=torch.bool)
                                    for key in ("done", "terminated", "truncated")})
        self._scenes = config.scenes.specs()
        self._lattices: dict[str, ViewLattice] = {}
        self._visibility: dict[str, tuple[SurfaceVisibility, np.ndarray, np.ndarray]] = {}  # centre, bins
        self._node_seen: dict[tuple[str, int], np.ndarray] = {}
        self._seen: np.ndarray | None = None  # the episode's seen surface samples (coverage reward)
        self._features = config.bov.feature_config()
        self.source = source or ViewSource(config.camera, config.render, self._features, config.obs_size,
                                           seed)
        check_source(self.source, config, self._features)
        self._bov: BagOfViews | None = None
        self._resume_pending = False
        self._view: Viewpoint | None = None
        self._return = torch.zeros(1)  # the episode's return so far (float32, summed as `RewardSum` does)
        self._novelty, self._metres = 0.0, 0.0  # the last view's novelty, the metres flown
        self._looked: np.ndarray | None = None  # where the episode has looked from (look_map)
        self._set_seed(seed)

    # -- TorchRL hooks -------------------------------------------------------------------------

    def _set_seed(self, seed: int | None) -> None:
        self._seed = int(seed or 0)
        self.source.reseed(self._seed)
        self._rng = np.random.default_rng(self._seed)
        self._episode = 0
        self._bov = None

    def _reset(self, tensordict: TensorDictBase | None = None, **kwargs) -> TensorDictBase:
        if self._resume_pending:
            # A restored snapshot continues its episode: the collector's first reset resumes it.
            self._resume_pending = False
            return self._observation().set(RETURN_KEY, self._return.clone())  # `EpisodeReturn` keeps it
        self._scene = self._scenes[(self.worker + self._episode) % len(self._scenes)]
        self.source.select(self._scene)
        self._episode += 1
        low, high = self.config.low, self.config.high
        self._view = draw_viewpoint(low, high, self._rng)
        self.bov.reset()
        frame, descriptors = self.capture(self._view)
        if self.config.bov_observation:  # the same update, its novelty kept
            self._novelty = novelty_of(self.bov.reward(descriptors, self._view.azimuth, self._view.elevation),
                                       self.bov)
        else:
            self.bov.update(descriptors, self._view.azimuth, self._view.elevation)
        self._metres = 0.0
        self._looked = look_of(self._view) if self.config.look_map else None
        if self._tracks_seen:
            self._seen = self.surface_seen(self._view).copy()  # ours to grow: the node's cache stays as is
        location = normalise_viewpoint(self._view, self.config)
        self._frames = np.repeat(frame[None], self.config.history, axis=0)
        self._locations = np.repeat(location[None], self.config.history, axis=0)
        self._progress = 0.0
        self._steps = 0
        self._return = torch.zeros(1)
        return self._observation()

    def _step(self, tensordict: TensorDictBase) -> TensorDictBase:
        view = action_to_viewpoint(tensordict["action"], self._view, self.config)
        frame, descriptors = self.capture(view)
        reward = bov_reward = self.bov.reward(descriptors, view.azimuth, view.elevation)
        if self._tracks_seen:
            seen = self.surface_seen(view)
            reward += self.reward_terms.coverage * float((seen & ~self._seen).mean())
            self._seen |= seen
        if self.reward_terms.flight or self.reward_terms.flight_excess or self.config.bov_observation:
            leg_m, terms = shell_path(self._view, [view]).total_m, self.reward_terms
            reward -= flight_cost(terms.flight, self._metres, leg_m, terms.flight_allowance,
                                  terms.flight_excess)
            self._metres += leg_m
            self._novelty = novelty_of(bov_reward, self.bov)
        if self.config.look_map:
            self._looked = np.maximum(self._looked, look_of(view))
        self._progress += wrap_angle(view.azimuth - self._view.azimuth)
        self._view = view
        self._steps += 1
        self._frames = np.concatenate([self._frames[1:], frame[None]])
        self._locations = np.concatenate([self._locations[1:], normalise_viewpoint(view, self.config)[None]])
        if self.config.episode_views:
            terminated = self._steps + 1 >= self.config.episode_views
        else:
            terminated = abs(self._progress) >= TWO_PI - 1e-9
        truncated = not terminated and self._steps >= self.config.max_steps
        out = self._observation(terminated, truncated)
        out.set("reward", torch.tensor([reward], dtype=torch.float32))
        self._return = self._return + out["reward"]  # as `RewardSum` sums it: a resume continues it exactly
        return out

    # -- state ---------------------------------------------------------------------------------

    @property
    def bov(self) -> BagOfViews:
        """The episode's Bag of Views (created on first use)."""
        if self._bov is None:
            bounds = (float(self.config.low[2]), float(self.config.high[2]))
            self._bov = BagOfViews.from_config(self.config.bov, seed=self._seed, elevation_bounds=bounds)
        return self._bov

    @property
    def views_rendered(self) -> int:
        """Views rendered since the seed was set (`render_seconds` is their wall time)."""
        return self.source.views_rendered

    @property
    def render_seconds(self) -> float:
        """Wall time of the views rendered (planning time without renders)."""
        return self.source.render_seconds

    @property
    def depths_rendered(self) -> int:
        """Depth images rendered since the seed was set (`depth_seconds` is their wall time)."""
        return self.source.depths_rendered

    @property
    def depth_seconds(self) -> float:
        """Wall time of the depth images rendered (`render_depth`)."""
        return self.source.depth_seconds

    @property
    def setup_seconds(self) -> float:
        """Wall time loading scenes into renderers (camera setup)."""
        return self.source.setup_seconds

    @property
    def scene(self) -> Scene:
        """The current scene, loaded (after the first reset)."""
        if self._view is None:
            raise RuntimeError("NBVEnv.scene needs an episode: call reset() first")
        return self.source.load(self._scene)

    @property
    def viewpoint(self) -> Viewpoint | None:
        """The current camera viewpoint (None before the first reset)."""
        return self._view

    def snapshot(self) -> dict[str, Any]:
        """The env's full runtime state (episode, its return so far, histories, RNG, BoV), loadable with
        weights_only."""
        if self._view is None:
            raise RuntimeError("NBVEnv.snapshot needs an episode: call reset() first")
        return {
            "seed": self._seed, "episode": self._episode, "views_rendered": self.source.views_rendered,
            "rng": self._rng.bit_generator.state, "scene": self._scene.scene,
            "view": self._view.as_array().tolist(), "frames": torch.from_numpy(self._frames.copy()),
            "locations": torch.from_numpy(self._locations.copy()),
            "progress": self._progress, "steps": self._steps, "bov": self.bov.state_dict(),
            "episode_return": self._return.clone(),
            **({"seen": torch.from_numpy(self._seen.copy())} if self._seen is not None else {}),
            "novelty": self._novelty, "metres": self._metres,
            **({"looked": torch.from_numpy(self._looked.copy())} if self.config.look_map else {}),
        }

    def restore(self, state: dict[str, Any]) -> None:
        """Load a `snapshot`; the next reset continues the restored episode instead of starting one."""
        self._set_seed(state["seed"])
        self._episode, self.source.views_rendered = int(state["episode"]), int(state["views_rendered"])
        self._rng.bit_generator.state = state["rng"]
        self._scene = SceneSpec(scene=str(state["scene"]), up_axis=self.config.scenes.up_axis)
        self.source.select(self._scene)
        self._view = Viewpoint(*map(float, state["view"]))
        self._frames, self._locations = state["frames"].numpy().copy(), state["locations"].numpy().copy()
        self._progress, self._steps = float(state["progress"]), int(state["steps"])
        self._return = state.get("episode_return", torch.zeros(1)).clone()  # older snapshots: restarts at 0
        self.bov.load_state_dict(state["bov"])
        self._seen = state["seen"].numpy().copy() if "seen" in state else None
        self._novelty, self._metres = float(state.get("novelty", 0.0)), float(state.get("metres", 0.0))
        self._looked = state["looked"].numpy().copy() if "looked" in state else None
        self._resume_pending = True

    # -- rendering -----------------------------------------------------------------------------

    def render_view(self, view: Viewpoint) -> np.ndarray:
        """The sRGB image at `view` of the current scene (advances the per-view render seed)."""
        return self.source.render_rgb(view)

    def render_depth(self, view: Viewpoint) -> np.ndarray:
        """The z-depth image at `view` of the current scene (H x W float32 metres, 0 for no hit): what a
        depth camera returns there. Always rendered, lattice or not."""
        return self.source.render_depth(view)

    def capture(self, view: Viewpoint) -> tuple[np.ndarray, torch.Tensor]:
        """The policy frame (S x S uint8) and SIFT descriptors (M, 128) of `view` of the current scene.

        Rendered, or with a lattice read from the cache at the nearest node.
        """
        apply_thread_policy()  # here, not in __init__: in the process that steps the env
        if self.blank_images:
            side = self.config.obs_size
            return np.zeros((side, side), dtype=np.uint8), torch.zeros(0, 128)
        if self.config.lattice.enabled:
            lattice = self._lattice(self._scene)
            return lattice.observe(lattice.snap(view)[1])
        return self.source.capture(view)

    def surface_seen(self, view: Viewpoint) -> np.ndarray:
        """Which of the current target's surface samples `view` sees (with a lattice: its node does, a
        read-only array cached per node)."""
        visibility, center, _ = self._target_samples()
        if not self.config.lattice.enabled:
            return visibility.seen(viewpoint_to_c2w(view, center))
        node, index = self._lattice(self._scene).snap(view)
        scene = self._scene.scene
        if (scene, index) not in self._node_seen:
            seen = visibility.seen(viewpoint_to_c2w(node, center))
            seen.setflags(write=False)  # shared by every episode that visits the node: never grown in place
            self._node_seen[scene, index] = seen
        return self._node_seen[scene, index]

    def _target_samples(self) -> tuple[SurfaceVisibility, np.ndarray, np.ndarray]:
        """The current target's surface visibility, centre and samples' unseen-map bins (on first use)."""
        scene = self._scene.scene
        if scene not in self._visibility:
            visibility, center = scene_visibility(self.scene, self.config.camera), self.scene.center()
            self._visibility[scene] = visibility, center, sample_bins(visibility.samples, center)
        return self._visibility[scene]

    def expert_scores(self) -> np.ndarray:
        """The privileged teacher's scores of its candidate steps from the current view (`nbv.rl.expert`):
        it reads the true surface, so training envs with an imitation term alone call it."""
        step = lambda action, view: action_to_viewpoint(action, view, self.config)  # noqa: E731
        views_left = (self.config.episode_views or self.config.max_steps + 1) - self._steps - 1
        terms = self.reward_terms
        return expert_scores(self._view, self._seen, self.surface_seen, step, terms.flight, views_left,
                             terms.teacher_horizon, terms.teacher_discount, flown_m=self._metres,
                             allowance_m=terms.flight_allowance, excess_weight=terms.flight_excess)

    def _teacher(self) -> dict[str, torch.Tensor]:
        """The state's teacher labels: its best step, and its near-ties with a `teacher_tolerance`."""
        keys = label_keys(self.reward_terms)
        if not keys:
            return {}
        scores = self.expert_scores()
        labels = {EXPERT_KEY: torch.from_numpy(best_action(scores))}
        if EXPERT_SET_KEY in keys:
            labels[EXPERT_SET_KEY] = torch.from_numpy(near_best(scores, self.reward_terms.teacher_tolerance))
        return labels

    def _lattice(self, spec: SceneSpec) -> ViewLattice:
        """The scene's lattice: read from the cache without a renderer, or rendered now."""
        if spec.scene not in self._lattices:
            self._lattices[spec.scene] = build_lattice(
                self.source.load(spec), lambda: self.source.renderer(spec), self.config, self._features,
                progress=False)
        return self._lattices[spec.scene]

    def _observation(self, terminated: bool = False, truncated: bool = False) -> TensorDict:
        unseen = unseen_map(self._target_samples()[2], self._seen) if self.config.privileged_unseen else None
        extra = {BOV_KEY: torch.from_numpy(bov_vector(self.bov, self._novelty, self._steps + 1, self._metres,
                                                      self.config, self._looked, unseen))
                 } if self.config.bov_observation else {}
        return TensorDict({
            "pixels": torch.from_numpy(self._frames.copy()),
            "viewpoints": torch.from_numpy(self._locations.astype(np.float32) * self.config.pose_observation),
            **extra,
            **self._teacher(),
            "done": torch.tensor([terminated or truncated]),
            "terminated": torch.tensor([terminated]),
            "truncated": torch.tensor([truncated]),
        }, batch_size=self.batch_size)

