"""Render settings: bad values refused naming the field, filter and resolution rules, records read back."""

import json
from dataclasses import asdict

import pytest

from common.provenance import config_from_record
from render.camera import UAVCamera
from render.settings import LightingSettings, RenderSettings, SensorSettings

BAD = [
    (lambda: RenderSettings(pixel_filter="bicubic"), "pixel_filter must be one of"),
    (lambda: RenderSettings(denoiser="optix"), "denoiser must be one of"),
    (lambda: RenderSettings(resolution_scale=0.0), r"resolution_scale must lie in \(0, 8\], got 0"),
    (lambda: RenderSettings(resolution_scale=float("nan")), "resolution_scale must lie in"),
    (lambda: RenderSettings(resolution_scale=9), "resolution_scale must lie in"),
    (lambda: RenderSettings(texture_scale=1.5), r"texture_scale must lie in \(0, 1\]"),
    (lambda: RenderSettings(texture_scale=0), "texture_scale must lie in"),
    (lambda: RenderSettings(variant="cuda_mono"), "variant must be one of"),
    (lambda: RenderSettings(motion_blur_m=-0.1), r"motion_blur_m must lie in \[0, 1\]"),
    (lambda: RenderSettings(motion_blur_frames=1), "motion_blur_frames must be in 2..64, got 1"),
    (lambda: LightingSettings(sky_model="hdri"), "sky_model must be one of"),
    (lambda: LightingSettings(light_mode="night"), "light_mode must be one of"),
    (lambda: LightingSettings(sun_elevation_deg=0.0), r"sun_elevation_deg must lie in \(0, 90\]"),
    (lambda: LightingSettings(sun_elevation_deg=95.0), "sun_elevation_deg must lie in"),
    (lambda: LightingSettings(sun_azimuth_deg=float("inf")), "sun_azimuth_deg must lie in"),
    (lambda: LightingSettings(turbidity=0.5), r"turbidity must lie in \[1, 10\]"),
    (lambda: SensorSettings(exposure_stops=21.0), "exposure_stops must lie in"),
    (lambda: SensorSettings(shot_noise=-0.1), r"shot_noise must lie in \[0, 1\]"),
    (lambda: SensorSettings(read_noise=2.0), "read_noise must lie in"),
    (lambda: SensorSettings(jpeg_quality=0), "jpeg_quality must be in 1..100, got 0"),
    (lambda: SensorSettings(jpeg_quality=101), "jpeg_quality must be in 1..100, got 101"),
    (lambda: SensorSettings(jpeg_quality=True), "jpeg_quality must be in 1..100"),
]


@pytest.mark.parametrize(("make", "message"), BAD, ids=[m.split(" ")[0] for _, m in BAD])
def test_bad_values_name_the_field(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_the_denoiser_renders_with_a_box_filter_unless_told():
    assert RenderSettings().rgb_filter == "gaussian"
    assert RenderSettings(denoiser="oidn").rgb_filter == "box"
    assert RenderSettings(denoiser="oidn", pixel_filter="tent").rgb_filter == "tent"
    assert RenderSettings(pixel_filter="lanczos").rgb_filter == "lanczos"


def test_resolution_scale_keeps_the_field_of_view():
    camera = UAVCamera(64, 48, 35.0)
    assert RenderSettings().render_camera(camera) is camera
    big = RenderSettings(resolution_scale=2.5).render_camera(camera)
    assert (big.width, big.height, big.focal_mm) == (160, 120, 35.0)
    assert big.fov_x_deg == pytest.approx(camera.fov_x_deg)
    assert big.fov_y_deg == pytest.approx(camera.fov_y_deg)
    tiny = RenderSettings(resolution_scale=0.001).render_camera(camera)
    assert (tiny.width, tiny.height) == (1, 1)


def test_a_record_round_trips_through_json_and_older_records_take_defaults():
    settings = RenderSettings(spp=8, denoiser="oidn", texture_scale=0.5,
                              lighting=LightingSettings("sunsky", "overcast", 30.0, 120.0, 4.0),
                              sensor=SensorSettings(1.0, 0.01, 0.005, 75))
    record = json.loads(json.dumps(asdict(settings)))
    assert config_from_record(RenderSettings, record) == settings
    old = {"spp": 4, "max_depth": 4, "integrator": "path", "variant": None, "seed": 0}
    assert config_from_record(RenderSettings, old) == RenderSettings(spp=4)
