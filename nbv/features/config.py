"""SIFT extraction settings, declared once: the Bag of Views rule nests them (`BoVRule.sift`).

Light on purpose (no torch, OpenCV or Kornia), so the command line builds its parser without loading
the extractors; `nbv.features.sift` holds the extraction itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal

from tyro.conf import Suppress, arg


@dataclass(frozen=True)
class FeatureConfig:
    """Settings of SIFT extraction (all but `device` and `batch_size` key the feature cache)."""

    backend: Annotated[Literal["kornia", "opencv"], arg(name="feature-backend")] = "kornia"
    """Feature extractor: Kornia (torch, batched, any device) or OpenCV (CPU)."""
    max_features: int = 500
    """Keep at most this many keypoints per view, the strongest by |DoG| response."""
    contrast_threshold: float = 0.04
    """OpenCV's SIFT contrast threshold; keypoints with |DoG| below it / 3 (image in [0, 1]) are dropped."""
    double_image: bool = False
    """Kornia: upsample the image 2x before the first octave (Lowe's octave -1; ~4x slower)."""
    device: Suppress[str] = "cpu"
    """Torch device of the Kornia backend and of the returned tensors (set from each command's --device)."""
    batch_size: Annotated[int, arg(name="feature-batch-size")] = 8
    """Kornia: views per forward pass (changes speed, not the features)."""

    def __post_init__(self) -> None:
        if self.backend not in ("kornia", "opencv"):
            raise ValueError(f"backend must be 'kornia' or 'opencv', got {self.backend!r}")
        if self.max_features < 1:
            raise ValueError(f"max_features must be >= 1, got {self.max_features}")
        if self.contrast_threshold < 0:
            raise ValueError(f"contrast_threshold must be >= 0, got {self.contrast_threshold}")
        if self.batch_size < 1:
            raise ValueError(f"batch_size must be >= 1, got {self.batch_size}")
