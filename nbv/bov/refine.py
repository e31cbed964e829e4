"""Offline dataset refinement with the Bag of Views (paper Alg. 1, Sec. VI-B, Table 2).

Walk a view dataset in its order; keep a view iff its BoV score is > 0, and
let only kept views update the vocabularies (docs/bov.md §5). The azimuth of
a frame is its recorded viewpoint's, else the one computed from its pose about
the dataset's centre. Features come from the on-disk cache, so a sweep over
(N, W) extracts them once (`nbv.bov.sweep`).

Beyond the paper, `--min-matches K` (`LinkSettings`, off by default) keeps the set registrable: the
paper's kept set, then the fewest dropped views needed so every kept view is linked to the first through
views sharing >= K verified SIFT matches (`nbv.sfm.repair`, docs/sfm.md §5); refine.json's `links`
records the paper's set, the added and the unlinked views.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import torch
from tyro.conf import Positional, arg

from common.io import check_output_folder, check_separate
from common.memory import check_memory
from common.provenance import config_record, run_record
from common.threads import set_torch_threads
from nbv.bov.bag import BagOfViews
from nbv.bov.config import BoVConfig, BoVRule
from nbv.features.cache import dataset_features
from nbv.features.sift import DESCRIPTOR_DIM, Features
from nbv.sfm.config import LinkSettings
from nbv.sfm.repair import repair_kept
from render.captures.dataset import CaptureDataset
from render.captures.frame import CaptureFrameConfig
from render.captures.open import read_views, write_kept
from render.dataset import ViewDataset
from render.viewpoint import c2w_to_viewpoint

FEATURE_BYTES = 2 * 4 * (DESCRIPTOR_DIM + 3)
"""Bytes one SIFT feature of a view takes while refining: float32 descriptor, keypoint and response, held
twice (the per-view features and the cache file's concatenation)."""

LINKS_NOTE = ("; with links (--min-matches): kept is the paper's kept set (links.paper_kept) plus "
              "links.added, the dropped views that link every kept view to the first")
"""What refine.json's note adds when the registrability repair ran."""

Progress = Callable[[int], None]
"""Called with a count of work just done (e.g. a tqdm bar's `update`)."""


@dataclass(frozen=True, kw_only=True)
class DatasetRun:
    """A run over a view dataset's features: what `nbv refine` and `nbv refine-sweep` share."""

    dataset: Annotated[Path, Positional, arg(metavar="DATASET")]
    """A view dataset folder (transforms.json, images/, depth/), e.g. from `nbv scan`, or a capture from
    another tool: a COLMAP model (ROOT with images/ and sparse/0/) or a nerfstudio transforms.json folder."""
    capture: CaptureFrameConfig = CaptureFrameConfig()
    """The target frame of a capture from another tool (ignored for our datasets, which record theirs)."""
    seed: int = 0
    """Seed of the reservoir and k-means++ draws."""
    device: str = "cpu"
    """Torch device of features and Bag of Views."""
    threads: int = 0
    """Torch CPU threads (0: torch's default, one per core); 1 on cores shared with other jobs
    (docs/conventions.md §9)."""
    cache_dir: Path | None = None
    """Feature cache folder (default: $NBV_CACHE_DIR/features or ~/.cache/nbv/features)."""

    def __post_init__(self) -> None:
        if self.seed < 0:
            raise ValueError(f"seed must be >= 0, got {self.seed}")
        if self.threads < 0:
            raise ValueError(f"threads must be >= 0 (0: torch's default), got {self.threads}")
        if not re.fullmatch(r"cpu|cuda(:\d+)?", self.device):
            raise ValueError(f"device must be cpu, cuda or cuda:N, got {self.device!r}")

    def settings(self, rule: BoVRule) -> dict[str, Any]:
        """The rule and this run's settings as one flat record (`settings` in refine.json, sweep.json)."""
        return {**config_record(rule), "seed": self.seed, "device": self.device,
                "cache_dir": None if self.cache_dir is None else str(self.cache_dir), "threads": self.threads}


@dataclass(frozen=True, kw_only=True)
class RefineConfig(DatasetRun):
    """Settings of `nbv refine`: a dataset, a Bag of Views of N ranges x W words, an output folder."""

    out: Path
    """Folder for the refined dataset and refine.json."""
    bov: BoVConfig = BoVConfig()
    """The Bag of Views: N, W and the rule."""
    links: LinkSettings = LinkSettings()
    """Registrability (beyond the paper, off by default): with --min-matches K, the paper's kept set plus the
    fewest dropped views that link every kept view to the first (`nbv.sfm.repair`)."""
    overwrite: bool = False
    """Replace the output folder if it is not empty."""

    def __post_init__(self) -> None:
        super().__post_init__()
        check_separate(self.out, self.dataset)


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


def refine_views(descriptors: Sequence[torch.Tensor], azimuths: Sequence[float],
                 bov: BagOfViews) -> RefineResult:
    """Paper Alg. 1 over views in order into the (empty) Bag of Views `bov`: keep iff score > 0, update
    only with kept views.

    Args:
        descriptors: per view, its (M, D) descriptors.
        azimuths: per view, its azimuth in radians.
        bov: the Bag of Views the kept views fill (N, W and the rule are its own).

    Example:
        >>> e = torch.eye(4)
        >>> refine_views([e[:2], e[:1], e[:0], e[2:3], e[3:4]], [0.5, 1.0, 4.0, 2.0, 3.5],
        ...              BagOfViews(2, 1, dim=4, match_cosine=0.5)).kept
        [0, 3, 4]
    """
    if len(descriptors) != len(azimuths):
        raise ValueError(f"{len(descriptors)} views but {len(azimuths)} azimuths")
    kept, scores = [], []
    for i, (desc, azimuth) in enumerate(zip(descriptors, azimuths)):
        score = bov.score(desc, float(azimuth))  # Alg. 1 lines 6-9
        scores.append(score)
        if score > 0:  # Alg. 1 line 10: a non-zero positive score keeps the view
            bov.update(desc, float(azimuth))  # lines 11-12
            kept.append(i)
    return RefineResult(kept, scores, [bov.range_of(float(a)) for a in azimuths])


def refine_with(rule: BoVRule, descriptors: Sequence[torch.Tensor], azimuths: Sequence[float], ranges: int,
                words: int, seed: int = 0, device: str | torch.device | None = None) -> RefineResult:
    """`refine_views` with a fresh Bag of Views of N = `ranges`, W = `words` under `rule`."""
    dim = descriptors[0].shape[-1] if len(descriptors) else DESCRIPTOR_DIM
    return refine_views(descriptors, azimuths, BagOfViews.from_rule(rule, ranges, words, seed, device, dim))


def load_views(run: DatasetRun, rule: BoVRule, progress: Progress | None = None
               ) -> tuple[ViewDataset, list[Features], np.ndarray]:
    """Read the run's dataset and its (cached) features and azimuths; fail clearly on an empty dataset."""
    if run.device.startswith("cuda") and int(run.device.partition(":")[2] or 0) >= torch.cuda.device_count():
        raise ValueError(f"device {run.device!r}: torch sees {torch.cuda.device_count()} CUDA GPU(s) here")
    dataset = read_views(run.dataset, run.capture)
    config = rule.feature_config(run.device)
    check_memory(f"refine of {len(dataset)} views of {run.dataset}", len(dataset),
                 config.max_features * FEATURE_BYTES, "refine fewer views or lower --max-features")
    if run.threads > 0:  # 0 leaves the process's choice (or the thread policy) as it was
        set_torch_threads(run.threads)
    feats = dataset_features(dataset, config, run.cache_dir, progress)
    return dataset, feats, frame_azimuths(dataset)


def _json_score(score: float) -> float | None:
    return None if math.isinf(score) else round(score, 6)


def refine_dataset(config: RefineConfig, progress: Progress | None = None) -> dict[str, Any]:
    """Refine `config.dataset` into `config.out`: the kept views as a dataset in the input's format
    (ours, a COLMAP model or a nerfstudio transforms.json), plus `refine.json`.

    `progress` is called with the number of views whose features were just extracted.
    Returns the summary written to `refine.json` (docs/data-formats.md §6): `kept` (source
    frame indices), `scores` (null for +inf), `ranges` (each source frame's range), settings, timing.
    """
    out = Path(config.out)
    check_output_folder(out, config.overwrite)  # fail before the work, not after
    start = time.perf_counter()
    dataset, feats, azimuths = load_views(config, config.bov, progress)
    result = refine_with(config.bov, [f.descriptors for f in feats], azimuths, config.bov.ranges,
                         config.bov.words, config.seed, config.device)
    kept, links = result.kept, {}
    if config.links.on:
        repair, record = repair_kept(feats, dataset.poses()[:, :3, 3], dataset.camera.K, kept, config.links)
        kept, links = repair.kept, {"links": record}
    settings = config.settings(config.bov)
    summary = {"dataset": str(config.dataset), "source_views": len(dataset), "kept_views": len(kept),
               "kept": kept, "scores": [_json_score(s) for s in result.scores],
               "ranges": result.ranges, "settings": settings, **links,
               "seconds": round(time.perf_counter() - start, 3),
               "note": "scores: null is +inf (first view of an empty range); a view is kept iff score > 0"
                       + (LINKS_NOTE if links else ""),
               **capture_record(dataset), **run_record("nbv refine", config)}
    write_kept(dataset, kept, out, {"refine": {"source": str(config.dataset), **settings}},
               config.overwrite, extra={"refine.json": summary})
    return summary


def capture_record(dataset: ViewDataset) -> dict[str, Any]:
    """`capture`: a capture's format and target frame, and `frame_files`: each frame's image (relative
    to the dataset) so kept indices can be traced; {} for our datasets."""
    if not isinstance(dataset, CaptureDataset):
        return {}
    files = [str(f.rgb_path.relative_to(dataset.root)) if f.rgb_path.is_relative_to(dataset.root)
             else str(f.rgb_path) for f in dataset.frames]
    return {"capture": dataset.meta["capture"], "frame_files": files}


def kept_view_grid(descriptors: Sequence[torch.Tensor], azimuths: Sequence[float], ranges: Sequence[int],
                   words: Sequence[int], rule: BoVRule = BoVRule(), seed: int = 0,
                   device: str | torch.device | None = None,
                   progress: Progress | None = None) -> dict[tuple[int, int], RefineResult]:
    """Alg. 1 for every (N, W) of the grid over the same features (paper Table 2): {(N, W): result}."""
    grid = {}
    for n in ranges:
        for w in words:
            grid[(n, w)] = refine_with(rule, descriptors, azimuths, n, w, seed, device)
            if progress is not None:
                progress(1)
    return grid
