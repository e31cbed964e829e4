"""The view source: the env's renders, features and clock, shareable between an env and a planner."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
from nbv.features.sift import extract_features
from nbv.features.source import ViewSource, gray_frame
from nbv.rl.config import EnvConfig
from nbv.rl.env import NBVEnv
from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.spec import SceneSet, SceneSpec

CONFIG = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                   render=RenderSettings(spp=2), obs_size=32,
                   bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")))
VIEWS = [Viewpoint(2.0, 0.3, 0.5), Viewpoint(1.8, 2.0, 0.7)]


def source(seed: int = 3) -> ViewSource:
    made = ViewSource(CONFIG.camera, CONFIG.render, CONFIG.bov.feature_config(), CONFIG.obs_size, seed)
    made.select(SceneSpec(scene="test_building"))
    return made


def test_view_k_renders_with_the_kth_seed_and_its_features_and_frame():
    views = source()
    frames = [views.capture(v) for v in VIEWS]
    renderer = MitsubaRenderer(views.scene, CONFIG.camera, RenderSettings(spp=2, seed=3))
    for k, (view, (frame, descriptors)) in enumerate(zip(VIEWS, frames)):
        seed = RenderSettings(spp=2, seed=3).view_seed(k)
        rgb = renderer.render_rgb(viewpoint_to_c2w(view, renderer.center), seed=seed)
        assert np.array_equal(frame, gray_frame(rgb, 32)) and frame.shape == (32, 32)
        expected = extract_features([rgb], CONFIG.bov.feature_config())[0].descriptors
        assert torch.equal(descriptors, torch.as_tensor(expected))
    assert views.views_rendered == 2 and views.render_seconds > 0 and views.setup_seconds > 0
    depth = views.render_depth(VIEWS[0])
    assert depth.shape == (48, 64) and views.depths_rendered == 1 and views.views_rendered == 2
    views.reseed(3)
    assert views.views_rendered == 0 and views.setup_seconds == 0.0
    assert np.array_equal(views.capture(VIEWS[0])[0], frames[0][0])  # seeds restart, the renderer is kept


def test_an_env_on_a_shared_source_renders_what_its_own_renders():
    shared = source(seed=0)
    own, on_shared = NBVEnv(CONFIG, seed=4), NBVEnv(CONFIG, seed=4, source=shared)
    first, second = own.reset(), on_shared.reset()
    assert torch.equal(first["pixels"], second["pixels"])
    assert shared.views_rendered == 1 and on_shared.views_rendered == 1 and on_shared.render_seconds > 0


def test_a_source_that_does_not_fit_the_env_is_refused():
    with pytest.raises(ValueError, match="obs_size"):
        NBVEnv(CONFIG, source=ViewSource(CONFIG.camera, CONFIG.render, CONFIG.bov.feature_config(), 16))
    with pytest.raises(ValueError, match="camera"):
        NBVEnv(CONFIG, source=ViewSource(UAVCamera(32, 24), CONFIG.render, CONFIG.bov.feature_config(), 32))
    with pytest.raises(RuntimeError, match="select"):
        ViewSource(CONFIG.camera, CONFIG.render, CONFIG.bov.feature_config()).capture(VIEWS[0])
