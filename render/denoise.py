"""Intel Open Image Denoise on a linear render, guided by albedo and normals (`mitsuba-oidn`).

`mitsuba-oidn` ships OIDN and its trained weights in its wheel (nothing is
downloaded) and runs on Dr.Jit's thread pool, so it adds no second pool beside
the renderer's (common/threads.py). It is imported on first use: renders without
the denoiser never load it.
"""

from __future__ import annotations

import numpy as np


def oidn_denoise(color: np.ndarray, albedo: np.ndarray | None = None,
                 normal: np.ndarray | None = None) -> np.ndarray:
    """The denoised linear HDR image (OIDN `RT` filter, high quality) of a noisy linear render.

    Args:
        color: H x W x 3 linear radiance, >= 0 (negative filter lobes are clipped here).
        albedo: H x W x 3 surface albedo in [0, 1] (the `aov` integrator's `albedo`), or None.
        normal: H x W x 3 shading normals in [-1, 1] (the `aov` integrator's `sh_normal`), or None;
            OIDN takes normals only together with an albedo.

    Returns:
        H x W x 3 float32 linear radiance.
    """
    try:
        import mitsuba_oidn
    except ImportError as err:
        raise ImportError("denoiser 'oidn' needs the mitsuba-oidn package (pip install mitsuba-oidn; "
                          "`make setup` installs it)") from err
    if normal is not None and albedo is None:
        raise ValueError("OIDN takes a normal guide only together with an albedo guide")
    guides = {name: None if image is None else np.ascontiguousarray(np.clip(image, lo, 1.0), np.float32)
              for name, image, lo in (("albedo", albedo, 0.0), ("normal", normal, -1.0))}
    out = mitsuba_oidn.denoise(np.ascontiguousarray(np.maximum(color, 0.0), np.float32), hdr=True, **guides)
    return np.asarray(out, dtype=np.float32)
