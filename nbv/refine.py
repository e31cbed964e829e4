"""Offline dataset refinement with the Bag of Views (paper Alg. 1, Sec. VI-B, Table 2).

Walk a view dataset in its order; keep a view iff its BoV score is > 0, and
let only kept views update the vocabularies (DESIGN section 3). The azimuth of
a frame is its recorded viewpoint's, else the one computed from its pose about
the dataset's centre. Features come from the on-disk cache, so a sweep over
(N, W) extracts them once.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import torch

from nbv.bov import DEFAULT_MATCH_COSINE, BagOfViews
from nbv.feature_cache import dataset_features
from nbv.features import FeatureConfig, Features
from nbv.provenance import config_record
from render.dataset import ViewDataset, check_output_folder, read_dataset, write_json, write_subset
from render.viewpoint import c2w_to_viewpoint


@dataclass(frozen=True)
class BoVOptions:
    """Feature and Bag-of-Views settings shared by `nbv refine` and `nbv refine-sweep`."""

    features: Literal["kornia", "opencv"] = "kornia"
    """SIFT backend."""
    max_features: int = 500
    """Keypoints kept per view, strongest first."""
    memory_cap: int = 2048
    """Descriptors held per azimuth range (reservoir sample) for the k-means updates."""
    match_cosine: float = DEFAULT_MATCH_COSINE
    """c of d = 1 - cos / c: a descriptor is new below this cosine to its nearest word (0.5: the paper's
    d = 1 - 2 cos, which keeps one view per range on SIFT; see nbv.bov)."""
    seed: int = 0
    """Seed of the reservoir and k-means++ draws."""
    device: str = "cpu"
    """Torch device of features and Bag of Views."""
    cache_dir: Path | None = None
    """Feature cache folder (default: $NBV_CACHE_DIR/features or ~/.cache/nbv/features)."""
    threads: int = 0
    """Torch CPU threads (0: torch's default, one per core). Set 1 on cores shared with other jobs:
    there 2 threads thrashed up to 15x, while on 2 idle cores they were 1.3x faster than 1."""

    def feature_config(self) -> FeatureConfig:
        """The feature extraction settings."""
        return FeatureConfig(backend=self.features, max_features=self.max_features, device=self.device)


@dataclass(frozen=True)
class RefineConfig(BoVOptions):
    """Settings of one refinement run."""

    ranges: int = 9
    """N, azimuth ranges (vocabularies) of the Bag of Views."""
    words: int = 20
    """W, visual words per range."""

    def __post_init__(self) -> None:
        if self.ranges < 1 or self.words < 1:
            raise ValueError(f"ranges and words must be >= 1, got N={self.ranges}, W={self.words}")


@dataclass(frozen=True)
class RefineResult:
    """The outcome of Alg. 1 over a sequence of views."""

    kept: list[int]
    """Indices of the kept views, in order."""
    scores: list[float]
    """Each view's score when it was reached (+inf: first view of its range)."""
    ranges: list[int]
    """Each view's azimuth range."""


def frame_azimuths(dataset: ViewDataset) -> np.ndarray:
    """Azimuth of every frame: its recorded viewpoint, else computed from its pose about the centre."""
    return np.array([f.viewpoint.azimuth if f.viewpoint is not None
                     else c2w_to_viewpoint(f.c2w, dataset.center).azimuth for f in dataset.frames])


def refine_views(descriptors: Sequence[torch.Tensor], azimuths: Sequence[float], ranges: int,
                 words: int, memory_cap: int = 2048, seed: int = 0,
                 device: str | torch.device | None = None,
                 match_cosine: float = DEFAULT_MATCH_COSINE) -> RefineResult:
    """Paper Alg. 1 over views in order: keep iff score > 0, update only with kept views.

    Args:
        descriptors: per view, its (M, D) descriptors.
        azimuths: per view, its azimuth in radians.
        ranges: N.
        words: W.
        memory_cap: descriptors held per range.
        seed: seed of the Bag of Views.
        device: torch device of the Bag of Views.
        match_cosine: c of the dissimilarity d = 1 - cos / c.

    Example:
        >>> e = torch.eye(4)
        >>> refine_views([e[:2], e[:1], e[:0], e[2:3], e[3:4]], [0.5, 1.0, 4.0, 2.0, 3.5], 2, 1,
        ...              match_cosine=0.5).kept
        [0, 3, 4]
    """
    if len(descriptors) != len(azimuths):
        raise ValueError(f"{len(descriptors)} views but {len(azimuths)} azimuths")
    dim = descriptors[0].shape[-1] if len(descriptors) else 128
    bov = BagOfViews(ranges, words, memory_cap=memory_cap, seed=seed, device=device, dim=dim,
                     match_cosine=match_cosine)
    kept, scores = [], []
    for i, (desc, azimuth) in enumerate(zip(descriptors, azimuths)):
        score = bov.score(desc, float(azimuth))  # Alg. 1 lines 6-9
        scores.append(score)
        if score > 0:  # Alg. 1 line 10: a non-zero positive score keeps the view
            bov.update(desc, float(azimuth))  # lines 11-12
            kept.append(i)
    return RefineResult(kept, scores, [bov.range_of(float(a)) for a in azimuths])


def load_views(dataset_path: str | Path, options: BoVOptions, progress: Callable[[int], None] | None = None
               ) -> tuple[ViewDataset, list[Features], np.ndarray]:
    """Read a dataset and its (cached) features and azimuths; fail clearly on an empty dataset."""
    dataset = read_dataset(dataset_path)
    if options.threads > 0:
        torch.set_num_threads(options.threads)
    feats = dataset_features(dataset, options.feature_config(), options.cache_dir, progress)
    return dataset, feats, frame_azimuths(dataset)


def _json_score(score: float) -> float | None:
    return None if math.isinf(score) else round(score, 6)


def refine_dataset(dataset_path: str | Path, out: str | Path, config: RefineConfig,
                   overwrite: bool = False,
                   progress: Callable[[int], None] | None = None) -> dict[str, Any]:
    """Refine a dataset folder into `out`: the kept views as a dataset, plus `out/refine.json`.

    Args:
        dataset_path: the source view dataset.
        out: the output folder (a dataset readable by `render.dataset.read_dataset`).
        config: feature and Bag-of-Views settings.
        overwrite: replace a non-empty `out`.
        progress: called with the number of views whose features were just extracted.

    Returns:
        The summary written to `refine.json`: `kept` (source frame indices), `scores`
        (null for +inf), `ranges` (each source frame's range), settings, timing.
    """
    out = Path(out)
    check_output_folder(out, overwrite)  # fail before the work, not after
    start = time.perf_counter()
    dataset, feats, azimuths = load_views(dataset_path, config, progress)
    result = refine_views([f.descriptors for f in feats], azimuths, config.ranges, config.words,
                          config.memory_cap, config.seed, config.device, config.match_cosine)
    settings = config_record(config)
    summary = {"dataset": str(dataset_path), "source_views": len(dataset), "kept_views": len(result.kept),
               "kept": result.kept, "scores": [_json_score(s) for s in result.scores],
               "ranges": result.ranges, "settings": settings,
               "seconds": round(time.perf_counter() - start, 3),
               "note": "scores: null is +inf (first view of an empty range); a view is kept iff score > 0"}
    write_subset(dataset, result.kept, out, {"refine": {"source": str(dataset_path), **settings}}, overwrite)
    write_json(out / "refine.json", summary)
    return summary


def kept_view_grid(descriptors: Sequence[torch.Tensor], azimuths: Sequence[float], ranges: Sequence[int],
                   words: Sequence[int], options: BoVOptions,
                   progress: Callable[[int], None] | None = None) -> dict[tuple[int, int], RefineResult]:
    """Alg. 1 for every (N, W) of the grid over the same features (paper Table 2).

    Returns:
        {(N, W): RefineResult}.
    """
    grid = {}
    for n in ranges:
        for w in words:
            grid[(n, w)] = refine_views(descriptors, azimuths, n, w, options.memory_cap, options.seed,
                                        options.device, options.match_cosine)
            if progress is not None:
                progress(1)
    return grid
