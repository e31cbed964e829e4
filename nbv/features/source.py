"""A view source: what a camera flying around a target returns at a viewpoint, with its render clock.

Shared by the RL env (`nbv.rl.env.NBVEnv`), the planners (`nbv.planning`) and
the validator, so every one of them renders, extracts features and counts
render time the same way. It holds the camera, one renderer per scene
(created lazily, on the first render of that scene, in the process that
renders), the feature extractor and the per-view render seed: the k-th RGB
view rendered since the seed was set is rendered with the render settings'
`view_seed(k)` under that seed. The scene it renders is the one last
`select`ed. Its clock (`render_seconds`, `views_rendered`, `depth_seconds`,
`depths_rendered`, `setup_seconds`) lets a planner's time be split into the
simulated camera and deciding (`nbv.planning.plan.choose_views`).
"""

from __future__ import annotations

import time
from dataclasses import replace

import cv2
import numpy as np
import torch

from common.threads import apply_thread_policy
from nbv.features.sift import FeatureConfig, Features, extract_features
from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.model import Scene
from scenes.spec import SceneSpec


def gray_frame(rgb: np.ndarray, size: int) -> np.ndarray:
    """An sRGB uint8 image as a `size` x `size` uint8 grayscale frame (area-averaged)."""
    gray = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY)
    return cv2.resize(gray, (size, size), interpolation=cv2.INTER_AREA)


class ViewSource:
    """Renders the selected scene at viewpoints and extracts their features, timing the renders.

    Args:
        camera: the camera of every view.
        render: render settings; their seed is replaced by `seed` (`reseed`).
        features: the SIFT settings of the descriptors.
        frame_size: side of the grayscale frame `capture` returns (the policy's observation).
        seed: seed of the per-view render seeds.
    """

    def __init__(self, camera: UAVCamera, render: RenderSettings, features: FeatureConfig,
                 frame_size: int = 64, seed: int = 0) -> None:
        self.camera, self.features, self.frame_size = camera, features, frame_size
        self._base_render = render
        self._renderers: dict[str, MitsubaRenderer] = {}
        self._loaded: dict[str, Scene] = {}
        self._scene: SceneSpec | None = None
        self.reseed(seed)

    def reseed(self, seed: int) -> None:
        """Restart the per-view render seeds under `seed` and zero the clock (renderers are kept)."""
        self.render = replace(self._base_render, seed=int(seed))
        self.views_rendered = 0  # RGB views rendered since the seed was set
        self.render_seconds = 0.0  # their wall time
        self.depths_rendered = 0  # depth images rendered since the seed was set
        self.depth_seconds = 0.0  # their wall time
        self.setup_seconds = 0.0  # wall time loading scenes into renderers (camera setup)

    def select(self, spec: SceneSpec) -> None:
        """Render `spec`'s scene from now on (loaded on first use)."""
        self._scene = spec

    @property
    def spec(self) -> SceneSpec:
        """The selected scene's spec."""
        if self._scene is None:
            raise RuntimeError("ViewSource has no scene: call select(spec) first")
        return self._scene

    @property
    def scene(self) -> Scene:
        """The selected scene, loaded."""
        return self.load(self.spec)

    def load(self, spec: SceneSpec) -> Scene:
        """A scene, loaded once (with its spec's up axis) and kept."""
        if spec.scene not in self._loaded:
            self._loaded[spec.scene] = spec.load()
        return self._loaded[spec.scene]

    def renderer(self, spec: SceneSpec) -> MitsubaRenderer:
        """The scene's renderer, created on first use (its time counts as camera setup)."""
        if spec.scene not in self._renderers:
            start = time.perf_counter()
            self._renderers[spec.scene] = MitsubaRenderer(self.load(spec), self.camera, self.render)
            self.setup_seconds += time.perf_counter() - start
        return self._renderers[spec.scene]

    def render_rgb(self, view: Viewpoint) -> np.ndarray:
        """The sRGB image at `view` of the selected scene (advances the per-view render seed)."""
        renderer = self.renderer(self.spec)
        seed = self.render.view_seed(self.views_rendered)
        self.views_rendered += 1
        start = time.perf_counter()
        rgb = renderer.render_rgb(viewpoint_to_c2w(view, renderer.center), seed=seed)
        self.render_seconds += time.perf_counter() - start
        return rgb

    def render_depth(self, view: Viewpoint) -> np.ndarray:
        """The z-depth image at `view` of the selected scene (H x W float32 metres, 0 for no hit): what a
        depth camera returns there."""
        renderer = self.renderer(self.spec)
        start = time.perf_counter()
        depth = renderer.render_depth(viewpoint_to_c2w(view, renderer.center))
        self.depth_seconds += time.perf_counter() - start
        self.depths_rendered += 1
        return depth

    def describe(self, rgb: np.ndarray) -> torch.Tensor:
        """The SIFT descriptors (M, 128) of an image."""
        apply_thread_policy()  # here: in the process that extracts, before Kornia picks its threads
        return torch.as_tensor(extract_features([rgb], self.features)[0].descriptors)

    def features_at(self, view: Viewpoint) -> Features:
        """The SIFT features (keypoints and descriptors) of the RGB image rendered at `view`: the same
        render and descriptors `capture` gives, for a planner that also matches views
        (`nbv.planning.linking`)."""
        apply_thread_policy()
        return extract_features([self.render_rgb(view)], self.features)[0]

    def capture(self, view: Viewpoint) -> tuple[np.ndarray, torch.Tensor]:
        """The grayscale frame (`frame_size` squared, uint8) and SIFT descriptors (M, 128) rendered at
        `view` of the selected scene."""
        apply_thread_policy()
        rgb = self.render_rgb(view)
        return gray_frame(rgb, self.frame_size), self.describe(rgb)
