"""From a linear render to the 8-bit image a camera delivers, in the physical order (docs/rendering.md).

    linear render -> denoise -> exposure -> sensor noise -> sRGB -> JPEG

The denoiser sees the renderer's own linear output (OIDN is trained on
unprocessed Monte Carlo noise; exposure, sensor noise, the sRGB curve or JPEG
blocks in front of it defeat it). Exposure scales the light reaching the
sensor, so it comes before the noise it changes the level of. Noise is drawn on
linear values: Poisson-Gaussian (Foi et al. 2008), `shot_noise * Poisson(x /
shot_noise) + N(0, read_noise^2)`, saturating at white (1.0) in the sRGB step.
The sRGB transfer curve and 8-bit quantisation are the camera's output; JPEG is
the last, lossy step. Each step is skipped at its neutral value, so default
settings give `srgb_to_uint8(linear)` exactly, as before these settings existed.
"""

from __future__ import annotations

import io

import numpy as np
from PIL import Image

from render.denoise import oidn_denoise
from render.settings import RenderSettings, SensorSettings

NOISE_STREAM = 0x4E4F4953
"""Second word of the sensor noise's seed sequence (the first is the view's render seed), so the noise is
not Mitsuba's sample stream."""


def srgb_to_uint8(linear: np.ndarray) -> np.ndarray:
    """Linear RGB in [0, 1] to 8-bit sRGB (the IEC 61966-2-1 transfer curve)."""
    c = np.clip(linear, 0.0, 1.0)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def expose(linear: np.ndarray, stops: float) -> np.ndarray:
    """`linear` times 2^stops (the same array at 0 stops)."""
    return linear if stops == 0.0 else linear * np.float32(2.0**stops)


def sensor_noise(linear: np.ndarray, shot_noise: float, read_noise: float, seed: int) -> np.ndarray:
    """Poisson-Gaussian noise on linear values, seeded: the same `seed` gives the same noise bit for bit.

    Args:
        linear: H x W x 3 linear values (negative values count as 0 photons).
        shot_noise: linear value of one photo-electron (1 / full well); 0 for no shot noise.
        read_noise: standard deviation of the Gaussian read noise, linear units; 0 for none.
        seed: the view's seed.
    """
    if shot_noise == 0.0 and read_noise == 0.0:
        return linear
    rng = np.random.default_rng([int(seed), NOISE_STREAM])
    signal = np.maximum(linear.astype(np.float64), 0.0)
    if shot_noise > 0.0:
        signal = shot_noise * rng.poisson(signal / shot_noise)
    if read_noise > 0.0:
        signal = signal + rng.normal(0.0, read_noise, signal.shape)
    return signal.astype(np.float32)


def jpeg_roundtrip(rgb: np.ndarray, quality: int | None) -> np.ndarray:
    """`rgb` (H x W x 3 uint8) encoded as JPEG at `quality` (1..100, PIL's 4:2:0) and decoded; None: as is."""
    if quality is None:
        return rgb
    buffer = io.BytesIO()
    Image.fromarray(rgb).save(buffer, format="JPEG", quality=int(quality))
    buffer.seek(0)
    with Image.open(buffer) as image:
        return np.asarray(image.convert("RGB"))


def camera_output(linear: np.ndarray, sensor: SensorSettings, seed: int) -> np.ndarray:
    """Exposure, sensor noise, sRGB and JPEG of a (denoised) linear H x W x 3 image: uint8 sRGB."""
    exposed = expose(linear, sensor.exposure_stops)
    noisy = sensor_noise(exposed, sensor.shot_noise, sensor.read_noise, seed)
    return jpeg_roundtrip(srgb_to_uint8(noisy), sensor.jpeg_quality)


def postprocess(linear: np.ndarray, settings: RenderSettings, seed: int, albedo: np.ndarray | None = None,
                normal: np.ndarray | None = None) -> np.ndarray:
    """The whole chain on one view: H x W x 3 linear render (+ guides for the denoiser) to uint8 sRGB.

    Args:
        linear: the renderer's linear RGB.
        settings: the render settings (`denoiser` and `sensor` are used here).
        seed: the view's render seed (seeds the sensor noise).
        albedo, normal: the denoiser's guides (H x W x 3), when `settings.denoiser` is on.
    """
    if settings.denoiser == "oidn":
        linear = oidn_denoise(linear, albedo, normal)
    return camera_output(linear, settings.sensor, seed)
