"""scripts/stereo_depth_eval.py: a view's stereo depth scored against the exact depth, one or more pairs."""

from __future__ import annotations

import numpy as np

from nbv.planning.world import PlanningWorld
from nbv.recon.stereo import StereoConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scripts import stereo_depth_eval
from tests.nbv.rl.test_bov_observation import config


def scores(sides: tuple[str, ...]) -> tuple[int, int, list]:
    world = PlanningWorld(config(camera=UAVCamera(160, 120), render=RenderSettings(spp=4)), seed=3)
    return stereo_depth_eval.score_view(world, world.start, 0.25, {"chosen": StereoConfig()}, None,
                                        sides)["chosen"]


def test_a_second_pair_measures_more_pixels_and_counts_both_pairs_depths():
    (inside, one, errors_one), (inside_two, two, errors_two) = scores(("back",)), scores(("back", "up"))
    assert inside == inside_two > 0  # the target's pixels do not depend on the pairs
    assert 0 < one < two <= inside  # the union of two pairs' measured pixels
    assert len(errors_one) == one and len(errors_two) > two  # pixels both pairs measure count twice
    assert np.median(errors_two) < 0.05  # the up pair's depths are as good: relative error, median
