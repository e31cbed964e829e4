"""OIDN on a synthetic noisy image: closer to the truth, guides accepted, a lone normal guide refused."""

import numpy as np
import pytest

from render.denoise import oidn_denoise

pytest.importorskip("mitsuba_oidn")


def noisy_ramp(seed=0):
    """A smooth horizontal ramp (the truth) and a copy with independent per-pixel noise, linear HDR."""
    truth = np.broadcast_to(np.linspace(0.1, 2.0, 64, dtype=np.float32)[None, :, None], (48, 64, 3)).copy()
    noise = np.random.default_rng(seed).normal(0.0, 0.2, truth.shape).astype(np.float32)
    return truth, np.maximum(truth + noise, 0.0)


def test_denoising_brings_a_noisy_image_closer_to_the_truth():
    truth, noisy = noisy_ramp()
    albedo = np.full_like(truth, 0.5)
    normal = np.broadcast_to(np.float32([0.0, 0.0, 1.0]), truth.shape).copy()
    for guides in ((), (albedo,), (albedo, normal)):
        out = oidn_denoise(noisy, *guides)
        assert out.shape == truth.shape and out.dtype == np.float32
        assert np.abs(out - truth).mean() < 0.5 * np.abs(noisy - truth).mean()


def test_a_normal_guide_needs_an_albedo_guide():
    _, noisy = noisy_ramp()
    with pytest.raises(ValueError, match="only together with an albedo"):
        oidn_denoise(noisy, None, np.zeros_like(noisy))
