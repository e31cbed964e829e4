"""How views are rendered: the render config every command that renders nests (one declaration).

`RenderSettings` holds the light transport (spp, integrator, pixel filter,
denoiser, resolution, texture detail, motion blur) and nests the lighting
(`LightingSettings`) and the simulated sensor (`SensorSettings`). Every default
reproduces the renders made before these settings existed, bit for bit; the
post-processing order is documented in `render.postprocess`. Flags are flat
(`nbv.cli.parse`): `--spp`, `--light-mode`, `--jpeg-quality`, ...
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, get_args

from tyro.conf import Suppress

from render.camera import UAVCamera
from render.variant import Variant

MAX_SPP = 65_536
"""Most samples per pixel (Mitsuba's samplers refuse counts near 2^32; 64k is far past converged)."""
MAX_RESOLUTION_SCALE = 8.0
"""Largest resolution scale (a 320x240 camera renders at most 2560x1920)."""
MAX_BLUR_FRAMES = 64
"""Most motion-blur sub-frames (each is a render)."""
MAX_EXPOSURE_STOPS = 20.0
"""Largest exposure change either way, stops (2^20 is a million times brighter or darker)."""

PixelFilter = Literal["gaussian", "box", "tent", "mitchell", "catmullrom", "lanczos"]
"""Mitsuba reconstruction filters of the RGB pass (`rfilter` plugins)."""
Denoiser = Literal["off", "oidn"]
"""Denoisers: none, or Intel Open Image Denoise (`mitsuba-oidn`, CPU or CUDA)."""
SkyModel = Literal["uniform", "sunsky"]
"""The scene's directional sun and uniform sky, or Mitsuba's Hosek-Wilkie `sunsky` (sun and sky)."""
LightMode = Literal["sun_and_sky", "overcast", "hard_sun"]
"""Which lights shine: both, the sky alone (overcast), the sun alone (hard shadows, black in shade)."""


def _check_choice(name: str, value: Any, kind: Any) -> None:
    choices = get_args(kind)
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")


def _check_number(name: str, value: Any, lo: float, hi: float, low_open: bool = False) -> None:
    """Refuse a non-number, NaN, infinity or a value outside [lo, hi] ((lo, hi] with `low_open`)."""
    ok = (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
          and (lo < value if low_open else lo <= value) and value <= hi)
    if not ok:
        interval = f"{'(' if low_open else '['}{lo:g}, {hi:g}]"
        raise ValueError(f"{name} must lie in {interval}, got {value!r}")


@dataclass(frozen=True)
class LightingSettings:
    """The lights of a generated scene (a Mitsuba XML scene keeps its own and refuses these)."""

    sky_model: SkyModel = "uniform"
    """Light model: the scene's directional sun and uniform sky, or Mitsuba's physical `sunsky` (Hosek-Wilkie
    sun and sky, scaled so a white ground receives the default lighting's brightness at 50 degrees)."""
    light_mode: LightMode = "sun_and_sky"
    """Lights that shine: sun and sky, overcast (sky only) or hard_sun (sun only)."""
    sun_elevation_deg: float | None = None
    """Sun elevation above the horizon, degrees in (0, 90]; default: the scene's own (50)."""
    sun_azimuth_deg: float | None = None
    """Sun azimuth, degrees counter-clockwise from +x in [-360, 360]; default: the scene's own (35)."""
    turbidity: float = 3.0
    """Atmospheric turbidity of the sunsky model, in [1, 10] (2: arctic clear, 3: clear, 10: hazy)."""

    def __post_init__(self) -> None:
        _check_choice("sky_model", self.sky_model, SkyModel)
        _check_choice("light_mode", self.light_mode, LightMode)
        if self.sun_elevation_deg is not None:
            _check_number("sun_elevation_deg", self.sun_elevation_deg, 0.0, 90.0, low_open=True)
        if self.sun_azimuth_deg is not None:
            _check_number("sun_azimuth_deg", self.sun_azimuth_deg, -360.0, 360.0)
        _check_number("turbidity", self.turbidity, 1.0, 10.0)


@dataclass(frozen=True)
class SensorSettings:
    """The simulated camera after the light arrives: exposure, sensor noise, JPEG (`render.postprocess`)."""

    exposure_stops: float = 0.0
    """Exposure change in stops: linear values are multiplied by 2^stops before noise and sRGB."""
    shot_noise: float = 0.0
    """Poisson (photon) noise: the linear value of one photo-electron, 1 / full-well capacity, in [0, 1]
    (0: none; 0.01 is a 100-electron well, very noisy)."""
    read_noise: float = 0.0
    """Gaussian read noise: standard deviation in linear units, in [0, 1] (0: none)."""
    jpeg_quality: int | None = None
    """JPEG quality 1..100 applied to the 8-bit image (datasets still store PNG); None: lossless."""

    def __post_init__(self) -> None:
        _check_number("exposure_stops", self.exposure_stops, -MAX_EXPOSURE_STOPS, MAX_EXPOSURE_STOPS)
        _check_number("shot_noise", self.shot_noise, 0.0, 1.0)
        _check_number("read_noise", self.read_noise, 0.0, 1.0)
        quality = self.jpeg_quality
        if quality is not None and (isinstance(quality, bool) or not isinstance(quality, int)
                                    or not 1 <= quality <= 100):
            raise ValueError(f"jpeg_quality must be in 1..100, got {quality!r}")


@dataclass(frozen=True)
class RenderSettings:
    """How RGB images are rendered (depth always uses one exact ray per pixel)."""

    spp: int = 16
    """Samples per pixel of the RGB pass, in [1, 65536]."""
    max_depth: int = 4
    """Longest light path (path integrator): 2 = direct light only."""
    integrator: Literal["path", "direct"] = "path"
    """Mitsuba integrator of the RGB pass."""
    pixel_filter: PixelFilter | None = None
    """Reconstruction filter of the RGB pass; default: gaussian, or box with a denoiser (depth: box)."""
    denoiser: Denoiser = "off"
    """Denoise the linear RGB render: off, or Intel Open Image Denoise with albedo and normal guides."""
    resolution_scale: float = 1.0
    """Render at this multiple of the camera's width and height, field of view kept, in (0, 8]."""
    texture_scale: float = 1.0
    """Downsample every scene texture to this fraction of its width and height, in (0, 1]."""
    motion_blur_m: float = 0.0
    """Camera travel while the shutter is open, metres sideways (camera x), in [0, 1]; 0: no motion blur."""
    motion_blur_frames: int = 8
    """Sub-frame poses averaged for motion blur, in [2, 64]; each renders spp / frames samples (min 1)."""
    lighting: LightingSettings = LightingSettings()
    """Sun and sky."""
    sensor: SensorSettings = SensorSettings()
    """Exposure, sensor noise and JPEG compression."""
    variant: Variant | None = None
    """Mitsuba variant; default: $NBV_VARIANT, else the fastest available (chosen per process)."""
    seed: Suppress[int] = 0
    """Base seed; view i of a scan is rendered with seed `seed * 1_000_003 + i`. Set from each command's
    own --seed, so it is no flag of its own."""

    def __post_init__(self) -> None:
        if not 1 <= self.spp <= MAX_SPP:
            raise ValueError(f"render spp must lie in [1, {MAX_SPP}], got {self.spp}")
        if self.max_depth < 1 and self.max_depth != -1:
            raise ValueError(f"render max_depth must be >= 1 (or -1), got {self.max_depth}")
        if self.integrator not in ("path", "direct"):
            raise ValueError(f"render integrator must be 'path' or 'direct', got {self.integrator!r}")
        if self.variant is not None:
            _check_choice("variant", self.variant, Variant)
        if self.pixel_filter is not None:
            _check_choice("pixel_filter", self.pixel_filter, PixelFilter)
        _check_choice("denoiser", self.denoiser, Denoiser)
        _check_number("resolution_scale", self.resolution_scale, 0.0, MAX_RESOLUTION_SCALE, low_open=True)
        _check_number("texture_scale", self.texture_scale, 0.0, 1.0, low_open=True)
        _check_number("motion_blur_m", self.motion_blur_m, 0.0, 1.0)
        frames = self.motion_blur_frames
        if isinstance(frames, bool) or not isinstance(frames, int) or not 2 <= frames <= MAX_BLUR_FRAMES:
            raise ValueError(f"motion_blur_frames must be in 2..{MAX_BLUR_FRAMES}, got {frames!r}")

    def view_seed(self, index: int) -> int:
        """The per-view seed of view `index` (Mitsuba uses seed 0 unless told)."""
        return (self.seed * 1_000_003 + index) % (2**31)

    @property
    def rgb_filter(self) -> PixelFilter:
        """The RGB pass's reconstruction filter: `pixel_filter`, else box with a denoiser, else gaussian.

        A denoiser wants noise that is independent from pixel to pixel; Mitsuba's gaussian filter (radius 2
        px) spreads each sample over its neighbours. Measured on test_building (64x48, PSNR against 1024 spp):
        OIDN lifts 4 spp from 24.7 to only 25.1 dB behind the gaussian filter, from 19.6 to 27.5 dB behind
        the box filter (1 spp: 19.0 -> 19.2 versus 14.6 -> 25.8 dB)."""
        if self.pixel_filter is not None:
            return self.pixel_filter
        return "box" if self.denoiser != "off" else "gaussian"

    def render_camera(self, camera: UAVCamera) -> UAVCamera:
        """The camera images are rendered with: `camera` at `resolution_scale` times its width and height
        (rounded, at least 1 pixel), the same lens, so the field of view is kept."""
        if self.resolution_scale == 1.0:
            return camera
        return camera.with_resolution(max(1, round(camera.width * self.resolution_scale)),
                                      max(1, round(camera.height * self.resolution_scale)))
