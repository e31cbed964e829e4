"""Post-processing of a linear render: each step against a hand-worked value, neutral steps exact, order."""

import numpy as np
import pytest

from render import postprocess as pp
from render.postprocess import (
    camera_output,
    expose,
    jpeg_roundtrip,
    postprocess,
    sensor_noise,
    srgb_to_uint8,
)
from render.settings import RenderSettings, SensorSettings


def linear_image(seed=0, shape=(48, 64, 3)):
    return np.random.default_rng(seed).uniform(0.0, 1.2, shape).astype(np.float32)


def test_srgb_transfer():
    np.testing.assert_array_equal(srgb_to_uint8(np.array([0.0, 0.0031308, 0.5, 1.0, 2.0])),
                                  [0, 10, 188, 255, 255])


def test_neutral_settings_are_exactly_the_srgb_of_the_render():
    linear = linear_image()
    out = postprocess(linear, RenderSettings(sensor=SensorSettings(0.0, 0.0, 0.0, None)), seed=5)
    np.testing.assert_array_equal(out, srgb_to_uint8(linear))
    assert expose(linear, 0.0) is linear and sensor_noise(linear, 0.0, 0.0, 5) is linear
    assert jpeg_roundtrip(out, None) is out


def test_exposure_doubles_per_stop():
    linear = linear_image()
    np.testing.assert_array_equal(expose(linear, 1.0), linear * 2)
    np.testing.assert_allclose(expose(linear, -2.0), linear / 4, rtol=1e-7)


def test_poisson_gaussian_noise_has_the_model_variance_and_is_seeded():
    flat = np.full((200, 200, 3), 0.25, np.float32)
    a, b = sensor_noise(flat, 0.01, 0.02, seed=3), sensor_noise(flat, 0.01, 0.02, seed=3)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, sensor_noise(flat, 0.01, 0.02, seed=4))
    # Var = shot * x + read^2 = 0.01 * 0.25 + 0.02^2 = 0.0029 (Foi et al. 2008); 120k samples.
    assert a.mean() == pytest.approx(0.25, abs=1e-3)
    assert a.var() == pytest.approx(0.0029, rel=0.03)
    shot = sensor_noise(flat, 0.01, 0.0, seed=3)
    np.testing.assert_allclose(shot / 0.01, np.round(shot / 0.01), atol=1e-3)  # whole photo-electrons


def test_noise_is_drawn_on_linear_values_after_exposure():
    linear = np.full((100, 100, 3), 0.1, np.float32)
    sensor = SensorSettings(exposure_stops=1.0, shot_noise=0.01)
    expected = srgb_to_uint8(sensor_noise(linear * 2, 0.01, 0.0, seed=9))
    np.testing.assert_array_equal(camera_output(linear, sensor, seed=9), expected)


def test_jpeg_is_the_last_step_and_lossy_by_quality():
    linear = linear_image(shape=(64, 64, 3))
    plain = srgb_to_uint8(linear)
    out = camera_output(linear, SensorSettings(jpeg_quality=50), seed=0)
    np.testing.assert_array_equal(out, jpeg_roundtrip(plain, 50))
    errors = [np.abs(jpeg_roundtrip(plain, q).astype(int) - plain).mean() for q in (95, 50, 10)]
    assert 0 < errors[0] < errors[1] < errors[2]


def test_denoiser_runs_first_on_the_linear_render(monkeypatch):
    seen = {}

    def fake_denoise(color, albedo, normal):
        seen["input"] = color
        return color * 0 + 0.5

    monkeypatch.setattr(pp, "oidn_denoise", fake_denoise)
    linear = linear_image()
    settings = RenderSettings(denoiser="oidn", sensor=SensorSettings(exposure_stops=1.0))
    out = postprocess(linear, settings, seed=0, albedo=linear, normal=linear)
    assert seen["input"] is linear
    np.testing.assert_array_equal(out, srgb_to_uint8(np.full_like(linear, 1.0)))
