"""Texture resolution as a render setting: a scene's textures downsampled before Mitsuba sees them.

Mitsuba linearises an 8-bit PNG when it loads it (sRGB curve); downsampling is
done after that, on linear values (area averaging, as a lower-resolution texture
photographed or baked at that size would be), and the result is handed to
Mitsuba as a linear float bitmap. At scale 1 the PNG is loaded by file name as
before, untouched.
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import cv2
import numpy as np


def texture_dict(mi: ModuleType, path: Path, scale: float = 1.0) -> dict:
    """The Mitsuba `bitmap` texture dict of the sRGB PNG at `path`, at `scale` times its width and height
    (rounded, at least 1 texel), tiled (wrap mode repeat)."""
    if scale == 1.0:
        return {"type": "bitmap", "filename": str(path), "wrap_mode": "repeat"}
    bitmap = mi.Bitmap(str(path)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    linear = np.asarray(bitmap, dtype=np.float32)
    height, width = linear.shape[:2]
    size = (max(1, round(width * scale)), max(1, round(height * scale)))
    small = cv2.resize(linear, size, interpolation=cv2.INTER_AREA)
    return {"type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(small.reshape(size[1], size[0], 3))),
            "wrap_mode": "repeat"}
