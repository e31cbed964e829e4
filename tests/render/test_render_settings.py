"""Rendering settings on a real scene (test_building, tiny images): what each one does to the image.

Measured references: a high-spp render of the same pose; SIFT repeatability
with ground-truth correspondences (same pose: keypoints found again in place).
"""

import json

import numpy as np
import pytest

from nbv.features.repeatability import repeatability
from nbv.features.sift import FeatureConfig, extract_features
from render.camera import UAVCamera
from render.capture import capture_dataset
from render.dataset import DatasetError, read_dataset
from render.quality import psnr, ssim
from render.renderer import MitsubaRenderer
from render.settings import LightingSettings, RenderSettings, SensorSettings
from render.texture_scale import texture_dict
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.model import Lighting, Material, Part, Scene

CAMERA = UAVCamera(64, 48)
VIEW = Viewpoint(2.0, 0.8, 0.5)
REFERENCE_SPP = 512


@pytest.fixture(scope="module")
def scene():
    return load_scene("test_building")


def render(scene, settings=RenderSettings(), camera=CAMERA, seed=1):
    renderer = MitsubaRenderer(scene, camera, settings)
    return renderer.render(viewpoint_to_c2w(VIEW, renderer.center), seed=seed)


def rgb(scene, settings=RenderSettings(), camera=CAMERA, seed=1):
    renderer = MitsubaRenderer(scene, camera, settings)
    return renderer.render_rgb(viewpoint_to_c2w(VIEW, renderer.center), seed=seed)


def test_psnr_and_ssim_rise_with_spp(scene):
    reference = rgb(scene, RenderSettings(spp=REFERENCE_SPP), seed=99)
    images = [rgb(scene, RenderSettings(spp=spp)) for spp in (1, 4, 16)]
    psnrs = [psnr(image, reference) for image in images]
    ssims = [ssim(image, reference) for image in images]
    # Measured (64x48, llvm): 19.0, 24.7, 30.3 dB; each 4x of spp gains ~6 dB, as 1/spp variance predicts.
    assert psnrs[0] + 4 < psnrs[1] and psnrs[1] + 4 < psnrs[2], psnrs
    assert ssims[0] < ssims[1] < ssims[2], ssims


def test_the_denoiser_raises_psnr_at_4_spp(scene):
    pytest.importorskip("mitsuba_oidn")
    reference = rgb(scene, RenderSettings(spp=REFERENCE_SPP, pixel_filter="box"), seed=99)
    noisy = rgb(scene, RenderSettings(spp=4, pixel_filter="box"))
    denoised = rgb(scene, RenderSettings(spp=4, denoiser="oidn"))  # box filter: the denoiser's default
    # Measured (64x48, llvm): 19.6 dB noisy, 27.5 dB denoised, against the box-filtered reference.
    assert psnr(denoised, reference) > psnr(noisy, reference) + 4
    assert ssim(denoised, reference) > ssim(noisy, reference)


def test_jpeg_50_lowers_sift_repeatability(scene):
    camera = UAVCamera(160, 120)
    lossless, depth = render(scene, RenderSettings(), camera)
    features = FeatureConfig(backend="opencv")
    lossy = [rgb(scene, RenderSettings(sensor=SensorSettings(jpeg_quality=q)), camera) for q in (95, 50)]
    found = [extract_features([image], features)[0].keypoints.numpy() for image in [lossless, *lossy]]
    pose = viewpoint_to_c2w(VIEW, scene.center())
    scores = [repeatability(found[0], other, depth, camera.K, pose) for other in found]
    # Measured (160x120, OpenCV SIFT, 1 px): 1.0 lossless, 0.90 at quality 95, 0.58 at quality 50.
    assert len(found[0]) > 50
    assert scores[0] == 1.0 and scores[1] > scores[2] and scores[2] < 0.8, scores


def test_zero_noise_and_exposure_reproduce_the_plain_render(scene):
    plain = rgb(scene)
    neutral = RenderSettings(sensor=SensorSettings(exposure_stops=0.0, shot_noise=0.0, read_noise=0.0))
    np.testing.assert_array_equal(rgb(scene, neutral), plain)
    noisy = RenderSettings(sensor=SensorSettings(shot_noise=0.002, read_noise=0.01))
    first, again, other = rgb(scene, noisy), rgb(scene, noisy), rgb(scene, noisy, seed=2)
    np.testing.assert_array_equal(first, again)  # seeded per view
    assert not np.array_equal(first, plain) and not np.array_equal(first - plain, other - rgb(scene, seed=2))
    brighter = rgb(scene, RenderSettings(sensor=SensorSettings(exposure_stops=1.0)))
    assert brighter.mean() > plain.mean() + 20


def test_resolution_scale_keeps_the_field_of_view(scene):
    image, depth = render(scene)
    big_image, big_depth = render(scene, RenderSettings(resolution_scale=2.0))
    assert big_image.shape == (96, 128, 3) and big_depth.shape == (96, 128)
    # The same view at twice the pixels: the building covers the same share of the frame.
    assert (big_depth > 0).mean() == pytest.approx((depth > 0).mean(), abs=0.02)


def test_texture_scale_blurs_the_texture_not_the_geometry(scene):
    image, depth = render(scene)
    coarse, coarse_depth = render(scene, RenderSettings(texture_scale=1 / 16))
    np.testing.assert_array_equal(coarse_depth, depth)
    assert not np.array_equal(coarse, image)
    # Fine texture detail averages out: less high-frequency energy inside the building.
    def detail(im):
        return np.abs(np.diff(im.astype(float), axis=1))[(depth[:, 1:] > 0) & (depth[:, :-1] > 0)].mean()
    assert detail(coarse) < detail(image)


def test_a_downsampled_texture_keeps_its_linear_mean(scene):
    renderer = MitsubaRenderer(scene, CAMERA)
    path = next(p.material.texture for p in scene.parts if p.material.texture is not None)
    mi = renderer.mi
    full = np.asarray(mi.Bitmap(str(path)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32,
                                                   srgb_gamma=False))
    small = np.asarray(texture_dict(mi, path, 0.25)["bitmap"])
    assert small.shape == (round(full.shape[0] / 4), round(full.shape[1] / 4), 3)
    np.testing.assert_allclose(small.mean(axis=(0, 1)), full.mean(axis=(0, 1)), rtol=0.02)
    assert texture_dict(mi, path) == {"type": "bitmap", "filename": str(path), "wrap_mode": "repeat"}


def marker_scene():
    """A grey floor with a red 10 cm square at the origin, lit from straight above."""
    def quad(name, half, color, z=0.0):
        corners = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], float)
        return Part(name, corners, np.array([[0, 1, 2], [0, 2, 3]]), Material(name, color=color))
    return Scene("marker", (quad("floor", 2.0, (0.5, 0.5, 0.5)), quad("red", 0.05, (1.0, 0.0, 0.0), 1e-3)),
                 Lighting(sun_elevation_deg=90.0))


def red_spread(image):
    """Centroid (x, y) and variance (x, y) in pixels^2 of the image's redness."""
    weight = np.clip(image[..., 0].astype(float) - image[..., 1], 0, None)
    ys, xs = np.mgrid[:image.shape[0], :image.shape[1]]
    centre = [(weight * c).sum() / weight.sum() for c in (xs, ys)]
    return centre, [(weight * (c - m) ** 2).sum() / weight.sum() for c, m in zip((xs, ys), centre)]


def test_motion_blur_smears_along_the_camera_x_axis():
    camera, travel = UAVCamera(96, 72), 0.1
    c2w = viewpoint_to_c2w(Viewpoint(1.5, 0.3, 1.2), np.zeros(3))
    sharp = MitsubaRenderer(marker_scene(), camera)
    blurred = MitsubaRenderer(marker_scene(), camera, RenderSettings(motion_blur_m=travel))
    centre, spread = red_spread(sharp.render_rgb(c2w, seed=1))
    blur_centre, blur_spread = red_spread(blurred.render_rgb(c2w, seed=1))
    # 8 sub-frames evenly over L = travel * fx / z pixels add L^2 (K^2 - 1) / (12 K^2) to the x variance
    # (z: the marker's depth); y and the centroid stay.
    z = sharp.render_depth(c2w)[int(round(centre[1])), int(round(centre[0]))]
    length = travel * camera.fx / z
    assert blur_spread[0] - spread[0] == pytest.approx(length**2 * 63 / (12 * 64), rel=0.15)
    assert blur_spread[1] == pytest.approx(spread[1], abs=0.3)
    np.testing.assert_allclose(blur_centre, centre, atol=0.2)
    np.testing.assert_array_equal(blurred.render_depth(c2w), sharp.render_depth(c2w))  # at the view's pose


def test_lighting_modes_light_the_scene_as_named(scene):
    both = rgb(scene).astype(float)
    hard = rgb(scene, RenderSettings(lighting=LightingSettings(light_mode="hard_sun"))).astype(float)
    overcast = rgb(scene, RenderSettings(lighting=LightingSettings(light_mode="overcast"))).astype(float)
    sunsky = rgb(scene, RenderSettings(lighting=LightingSettings(sky_model="sunsky"))).astype(float)
    assert both.mean() > hard.mean() and both.mean() > overcast.mean()
    assert np.percentile(hard, 5) < np.percentile(both, 5)  # shadows go black without the sky
    assert 40 < sunsky.mean() < 220  # calibrated to the default lighting's brightness
    low = rgb(scene, RenderSettings(lighting=LightingSettings(sun_elevation_deg=15.0, sun_azimuth_deg=200.0)))
    assert psnr(low, rgb(scene)) < 25


def test_settings_are_recorded_in_transforms_json(scene, tmp_path):
    settings = RenderSettings(spp=2, resolution_scale=0.5, texture_scale=0.5,
                              lighting=LightingSettings(light_mode="overcast", sun_elevation_deg=40.0),
                              sensor=SensorSettings(exposure_stops=0.5, shot_noise=0.001, jpeg_quality=80))
    views = [Viewpoint(2.0, 0.0, 0.4), Viewpoint(2.0, 1.5, 0.6)]
    out = capture_dataset(scene, CAMERA, views, tmp_path / "ds", settings, progress=False)
    doc = json.loads((out / "transforms.json").read_text())
    assert (doc["w"], doc["h"]) == (32, 24)
    record = doc["nbv"]["render"]
    assert (record["spp"], record["resolution_scale"], record["texture_scale"]) == (2, 0.5, 0.5)
    assert record["lighting"] == {"sky_model": "uniform", "light_mode": "overcast", "sun_elevation_deg": 40.0,
                                  "sun_azimuth_deg": None, "turbidity": 3.0}
    assert record["sensor"] == {"exposure_stops": 0.5, "shot_noise": 0.001, "read_noise": 0.0,
                                "jpeg_quality": 80}
    dataset = read_dataset(out)
    assert dataset.render_settings == settings and dataset.rgb(1).shape == (24, 32, 3)
    record["sensor"]["jpeg_quality"] = 0
    (out / "transforms.json").write_text(json.dumps(doc))
    with pytest.raises(DatasetError, match="nbv.render: jpeg_quality must be in 1..100"):
        read_dataset(out)
    record["sensor"]["jpeg_quality"], record["bloom"] = 80, 1.0
    (out / "transforms.json").write_text(json.dumps(doc))
    with pytest.raises(DatasetError, match="nbv.render: RenderSettings has no field.*bloom"):
        read_dataset(out)


def test_a_mitsuba_xml_scene_refuses_lighting_settings(tmp_path):
    xml = tmp_path / "scene.xml"
    xml.write_text('<scene version="3.0.0"><emitter type="constant"/></scene>')
    with pytest.raises(ValueError, match="lighting settings and texture_scale do not apply"):
        MitsubaRenderer(Scene("xml", (), mitsuba_xml=xml), CAMERA,
                        RenderSettings(lighting=LightingSettings(light_mode="overcast")))
