"""Procedural textures: size, determinism by seed, tiling, the on-disk cache."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from scenes.noise import fbm, voronoi
from scenes.textures import TEXTURE_SIZE, TEXTURES, make_texture, texture_path


def test_every_texture_is_deterministic_and_seed_dependent():
    for name in ("brick_red", "roof_tiles_red", "gravel"):
        a, b, c = make_texture(name, 3, 128), make_texture(name, 3, 128), make_texture(name, 4, 128)
        assert a.shape == (128, 128, 3) and a.dtype == np.uint8
        assert np.array_equal(a, b)
        assert not np.array_equal(a, c)


def test_required_kinds_exist_at_1024_px():
    assert TEXTURE_SIZE >= 1024
    for kind in ("brick", "stone", "plaster", "timber", "roof", "grass", "gravel"):
        assert any(kind in name for name in TEXTURES), kind


def test_textures_carry_high_frequency_detail():
    image = make_texture("plaster_white", 0, 256).astype(np.float64).mean(axis=2)
    # Pixel-to-pixel differences: real detail, not a flat colour.
    assert np.abs(np.diff(image, axis=1)).mean() > 2.0


def test_noise_is_periodic():
    rng = np.random.default_rng(0)
    field = fbm(64, rng, beta=2.0)
    # The wrap-around step is no larger than a typical neighbour step.
    assert np.abs(field[:, 0] - field[:, -1]).mean() < 2 * np.abs(np.diff(field, axis=1)).mean()
    _, _, ident = voronoi(64, 4, rng)
    assert set(np.unique(ident)) <= set(range(16))


def test_cache_is_keyed_by_seed_and_hash_equal_across_caches(fresh_cache, tmp_path, monkeypatch):
    first = texture_path("gravel", 7)
    assert first.is_relative_to(fresh_cache) and f"{TEXTURE_SIZE}px" in first.name
    mtime = first.stat().st_mtime_ns
    assert texture_path("gravel", 7).stat().st_mtime_ns == mtime  # served from the cache
    assert texture_path("gravel", 8) != first
    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path / "other"))
    second = texture_path("gravel", 7)
    assert second != first
    assert hashlib.sha256(second.read_bytes()).digest() == hashlib.sha256(first.read_bytes()).digest()


def test_unknown_texture_is_rejected():
    with pytest.raises(ValueError, match="unknown texture 'marble'"):
        make_texture("marble", 0)
