"""PSNR and SSIM against hand-worked values."""

import numpy as np
import pytest

from render.quality import psnr, ssim


def test_psnr_of_a_constant_offset():
    ref = np.full((20, 30, 3), 100, np.uint8)
    # MSE = 10^2 = 100: PSNR = 10 log10(255^2 / 100) = 28.1308 dB.
    assert psnr(ref + 10, ref) == pytest.approx(28.1308, abs=1e-4)
    unit = ref.astype(np.float32) / 255
    assert psnr(unit, unit + 0.5) == pytest.approx(6.0206, abs=1e-4)  # peak 1, MSE 0.25
    assert psnr(ref, ref) == float("inf")


def test_ssim_of_flat_images_is_the_luminance_term():
    # Flat images have no variance: SSIM = (2 mu_x mu_y + C1) / (mu_x^2 + mu_y^2 + C1), C1 = (0.01 * 255)^2.
    a, b = np.full((16, 16), 100, np.uint8), np.full((16, 16), 120, np.uint8)
    c1 = (0.01 * 255) ** 2
    assert ssim(a, b) == pytest.approx((2 * 100 * 120 + c1) / (100**2 + 120**2 + c1), rel=1e-9)


def test_ssim_is_one_for_identical_images_and_falls_with_noise():
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (32, 40, 3)).astype(np.uint8)
    assert ssim(image, image) == pytest.approx(1.0)
    noisy = np.clip(image + rng.normal(0, 20, image.shape), 0, 255).astype(np.uint8)
    noisier = np.clip(image + rng.normal(0, 60, image.shape), 0, 255).astype(np.uint8)
    assert 1.0 > ssim(noisy, image) > ssim(noisier, image)


def test_mismatched_or_tiny_images_are_refused():
    with pytest.raises(ValueError, match="shape"):
        psnr(np.zeros((4, 4), np.uint8), np.zeros((4, 5), np.uint8))
    with pytest.raises(ValueError, match="dtype"):
        psnr(np.zeros((4, 4), np.uint8), np.zeros((4, 4), np.float32))
    with pytest.raises(ValueError, match="at least 11"):
        ssim(np.zeros((8, 8), np.uint8), np.zeros((8, 8), np.uint8))


def test_ssim_and_psnr_agree_with_kornia():
    torch = pytest.importorskip("torch")
    kornia = pytest.importorskip("kornia")
    rng = np.random.default_rng(1)
    image = rng.integers(0, 256, (40, 50, 3)).astype(np.uint8)
    noisy = np.clip(image + rng.normal(0, 25, image.shape), 0, 255).astype(np.uint8)

    def tensor(x):
        return torch.from_numpy(x.astype(np.float32) / 255).permute(2, 0, 1)[None]

    expected = kornia.metrics.ssim(tensor(noisy), tensor(image), 11, padding="valid").mean().item()
    assert ssim(noisy, image) == pytest.approx(expected, abs=1e-6)
    assert psnr(noisy, image) == pytest.approx(kornia.metrics.psnr(tensor(noisy), tensor(image), 1.0).item(),
                                               abs=1e-4)
