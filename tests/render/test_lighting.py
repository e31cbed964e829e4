"""Emitter dicts of the lighting settings: the defaults are the historical lights, modes drop lights."""

import numpy as np
import pytest

from render.lighting import SUNSKY_SCALE, scene_emitters
from render.settings import LightingSettings
from scenes.model import Lighting


def test_default_lights_are_the_scenes_sun_and_uniform_sky():
    light = Lighting()
    assert scene_emitters(light) == {
        "sun": {"type": "directional", "direction": light.sun_direction().tolist(),
                "irradiance": {"type": "rgb", "value": [3.0, 3.0, 3.0]}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.55, 0.6, 0.7]}},
    }


def test_overcast_is_sky_only_and_hard_sun_is_sun_only():
    assert list(scene_emitters(Lighting(), LightingSettings(light_mode="overcast"))) == ["sky"]
    assert list(scene_emitters(Lighting(), LightingSettings(light_mode="hard_sun"))) == ["sun"]


def test_sun_angles_override_the_scenes():
    sun = scene_emitters(Lighting(), LightingSettings(sun_elevation_deg=90.0))["sun"]
    np.testing.assert_allclose(sun["direction"], [0.0, 0.0, -1.0], atol=1e-12)
    sun = scene_emitters(Lighting(), LightingSettings(sun_elevation_deg=30.0, sun_azimuth_deg=180.0))["sun"]
    # Light travels away from the sun: from azimuth 180 (-x), 30 degrees up, towards +x and down.
    np.testing.assert_allclose(sun["direction"], [np.cos(np.pi / 6), 0.0, -0.5], atol=1e-12)


@pytest.mark.parametrize(("mode", "sun", "sky"), [("sun_and_sky", SUNSKY_SCALE, SUNSKY_SCALE),
                                                  ("overcast", 0.0, SUNSKY_SCALE),
                                                  ("hard_sun", SUNSKY_SCALE, 0.0)])
def test_sunsky_points_at_the_sun_and_scales_its_parts(mode, sun, sky):
    lights = scene_emitters(Lighting(sun_elevation_deg=90.0), LightingSettings("sunsky", mode, turbidity=5.0))
    assert list(lights) == ["sky"]
    emitter = lights["sky"]
    np.testing.assert_allclose(emitter["sun_direction"], [0.0, 0.0, 1.0], atol=1e-12)  # towards the sun
    assert (emitter["type"], emitter["turbidity"], emitter["sun_scale"], emitter["sky_scale"]) == \
        ("sunsky", 5.0, sun, sky)
