"""The Bag of Views config, declared once: refinement, the sweep, the RL reward and the greedy planner.

Light on purpose (no torch), so the command line builds its parser without
loading the models. `docs/bov.md` states the rule these knobs control.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Literal

from tyro.conf import arg

if TYPE_CHECKING:
    from nbv.bov.bag import BagOfViews
    from nbv.features.sift import FeatureConfig

DEFAULT_MATCH_COSINE = 0.8
"""c of d = 1 - cos / c; measured on our SIFT scans (docs/bov.md §4). 0.5 is the paper's Eq. 1."""
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
    memory_cap: Annotated[int, arg(aliases=("--bov-memory",))] = 2048
    """Descriptors held per azimuth range (reservoir sample) for the k-means updates."""
    kmeans_iters: int = 10
    """Most Lloyd rounds of one k-means update of a range's words."""
    features: Annotated[Literal["kornia", "opencv"], arg(aliases=("--feature-backend",))] = "kornia"
    """SIFT backend."""
    max_features: int = 500
    """Keypoints kept per view, strongest first."""

    def __post_init__(self) -> None:
        if not 0.0 < self.match_cosine <= 1.0:
            raise ValueError(f"match_cosine must lie in (0, 1], got {self.match_cosine}")
        for name in ("memory_cap", "kmeans_iters", "max_features"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")

    def feature_config(self, device: str = "cpu") -> FeatureConfig:
        """The SIFT extraction settings."""
        from nbv.features.sift import FeatureConfig

        return FeatureConfig(backend=self.features, max_features=self.max_features, device=device)

    def make_bag(self, ranges: int, words: int, seed: int = 0, device: str = "cpu", bands: int = 1,
                 elevation_bounds: tuple[float, float] | None = None) -> BagOfViews:
        """An empty Bag of Views of N = `ranges` (x E = `bands`) vocabularies of W = `words` words."""
        from nbv.bov.bag import BagOfViews

        return BagOfViews(ranges, words, self.memory_cap, seed=seed, device=device,
                          kmeans_iters=self.kmeans_iters, match_cosine=self.match_cosine, bands=bands,
                          elevation_bounds=elevation_bounds)


def check_size(ranges: int, words: int) -> None:
    """Refuse (ValueError naming the field) N outside [1, MAX_RANGES] or W outside [1, MAX_WORDS]."""
    if not (1 <= ranges <= MAX_RANGES and 1 <= words <= MAX_WORDS):
        raise ValueError(f"ranges and words must be >= 1 and at most {MAX_RANGES} and {MAX_WORDS}, "
                         f"got N={ranges}, W={words}")


@dataclass(frozen=True)
class BoVConfig(BoVRule):
    """A Bag of Views of a given size under the rule (paper Table 2's N and W)."""

    ranges: Annotated[int, arg(aliases=("--bov-ranges",))] = 9
    """N, azimuth ranges (vocabularies) of the Bag of Views."""
    words: Annotated[int, arg(aliases=("--bov-words",))] = 20
    """W, visual words per range."""
    elevation_bands: int = 1
    """E, elevation bands per azimuth range of the online reward (1: the paper's azimuth-only ranges; 2
    tells a high view from a low one). Beyond the paper; offline refinement (Alg. 1) uses azimuth only."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.elevation_bands < 1:
            raise ValueError(f"elevation_bands must be >= 1, got {self.elevation_bands}")
        check_size(self.ranges * self.elevation_bands, self.words)

    def bag(self, seed: int = 0, device: str = "cpu",
            elevation_bounds: tuple[float, float] | None = None) -> BagOfViews:
        """An empty Bag of Views of this size (`elevation_bounds`, radians, split into the E bands)."""
        return self.make_bag(self.ranges, self.words, seed, device, self.elevation_bands, elevation_bounds)
