"""The Bag of Views config, declared once: refinement, the sweep, the RL reward and the greedy planner.

Light on purpose (no torch), so the command line builds its parser without loading
the models. `docs/bov.md` states the rule these knobs control; `BagOfViews.from_rule`
and `BagOfViews.from_config` (`nbv.bov.bag`) build a Bag of Views from them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from nbv.features.config import FeatureConfig

DEFAULT_MATCH_COSINE = 0.78
"""c of d = 1 - cos / c; chosen on the training presets' full scans in the detailed look (docs/bov.md §4,
paper_results/match_cosine). 0.5 is the paper's Eq. 1."""
DEFAULT_MEMORY_CAP = 2048
"""Descriptors held per azimuth range by default."""
DEFAULT_KMEANS_ITERS = 10
"""Most Lloyd rounds of one vocabulary update by default."""
MAX_RANGES = 360
"""Most azimuth ranges N (one per degree); more only allocates empty vocabularies."""
MAX_WORDS = 10_000
"""Most words W per range (a view has at most a few thousand descriptors)."""


@dataclass(frozen=True)
class BoVRule:
    """The Bag of Views rule and its features, whatever its size: all but N and W."""

    match_cosine: float = DEFAULT_MATCH_COSINE
    """c of d = 1 - cos / c: a descriptor is new below this cosine to its nearest word (0.5: the paper's
    d = 1 - 2 cos, which keeps one view per range on SIFT; see docs/bov.md)."""
    memory_cap: int = DEFAULT_MEMORY_CAP
    """Descriptors held per azimuth range (reservoir sample) for the k-means updates."""
    kmeans_iters: int = DEFAULT_KMEANS_ITERS
    """Most Lloyd rounds of one k-means update of a range's words."""
    sift: FeatureConfig = FeatureConfig()
    """The SIFT features the rule counts: backend, keypoints per view, contrast threshold, doubling."""

    def __post_init__(self) -> None:
        if not 0.0 < self.match_cosine <= 1.0:
            raise ValueError(f"match_cosine must lie in (0, 1], got {self.match_cosine}")
        for name in ("memory_cap", "kmeans_iters"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")

    def feature_config(self, device: str = "cpu") -> FeatureConfig:
        """The SIFT extraction settings, on the torch `device` of the command."""
        return replace(self.sift, device=device)

    @staticmethod
    def upgrade_record(record: dict[str, Any]) -> dict[str, Any]:
        """A record written before the SIFT settings were nested (top-level `features` and
        `max_features`, e.g. the shipped policy's) in today's layout; today's records pass unchanged."""
        moved = {"features": "backend", "max_features": "max_features"}
        if not set(moved) & set(record):
            return record
        sift = {new: record[old] for old, new in moved.items() if old in record}
        kept = {k: v for k, v in record.items() if k not in moved}
        return {**kept, "sift": {**sift, **kept.get("sift", {})}}


def check_size(ranges: int, words: int) -> None:
    """Refuse (ValueError naming the field) N outside [1, MAX_RANGES] or W outside [1, MAX_WORDS]."""
    if not (1 <= ranges <= MAX_RANGES and 1 <= words <= MAX_WORDS):
        raise ValueError(f"ranges and words must be >= 1 and at most {MAX_RANGES} and {MAX_WORDS}, "
                         f"got N={ranges}, W={words}")


@dataclass(frozen=True)
class BoVConfig(BoVRule):
    """A Bag of Views of a given size under the rule (paper Table 2's N and W)."""

    ranges: int = 9
    """N, azimuth ranges (vocabularies) of the Bag of Views."""
    words: int = 20
    """W, visual words per range."""
    elevation_bands: int = 1
    """E, elevation bands per azimuth range of the online reward (1: the paper's azimuth-only ranges; 2
    tells a high view from a low one). Beyond the paper; offline refinement (Alg. 1) uses azimuth only."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.elevation_bands < 1:
            raise ValueError(f"elevation_bands must be >= 1, got {self.elevation_bands}")
        check_size(self.ranges * self.elevation_bands, self.words)
