"""Settings of the structure-from-motion check (`nbv sfm`): COLMAP's pipeline through pycolmap."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

from tyro.conf import Positional, arg


@dataclass(frozen=True)
class SfmSettings:
    """How COLMAP reconstructs a view set: features, matching, incremental mapping with fixed intrinsics."""

    matching: Literal["exhaustive", "spatial"] = "exhaustive"
    """Image pairs matched: every pair, or each view with its nearest views by position (the dataset's
    poses, or the GNSS positions with --gnss-noise-m: for large sets)."""
    spatial_neighbours: int = 20
    """Nearest views by position each view is matched with under --matching spatial."""
    sift_max_features: int = 8192
    """Most SIFT features COLMAP extracts per image (COLMAP's default 8192)."""
    gnss_noise_m: float | None = None
    """Position priors as a UAV's GNSS gives them: each true camera centre plus seeded Gaussian noise of
    this standard deviation per axis, metres, used in COLMAP's bundle adjustment (the model comes out in
    the world frame); None: no priors."""
    colmap_threads: int = 0
    """Threads of COLMAP's extraction, matching and mapping; 0: the cores this process may use."""
    colmap_log: bool = False
    """Print COLMAP's own log to stderr (off: only fatal errors)."""

    def __post_init__(self) -> None:
        if self.spatial_neighbours < 1:
            raise ValueError(f"spatial_neighbours must be >= 1, got {self.spatial_neighbours}")
        if self.sift_max_features < 1:
            raise ValueError(f"sift_max_features must be >= 1, got {self.sift_max_features}")
        noise = self.gnss_noise_m
        if noise is not None and not (math.isfinite(noise) and noise > 0):
            raise ValueError(f"gnss_noise_m must be a positive number of metres (omit it for no priors), "
                             f"got {noise}")
        if self.colmap_threads < 0:
            raise ValueError(f"colmap_threads must be >= 0 (0: the usable cores), got {self.colmap_threads}")


@dataclass(frozen=True)
class LinkSettings:
    """Registrability as a constraint of refinement and planning (beyond the paper; docs/sfm.md §5): a view
    is kept or flown only if it shares enough geometrically verified SIFT matches with one already kept or
    flown, so the set stays one connected match graph, as incremental structure from motion needs."""

    min_matches: int = 0
    """K: a view is kept (`nbv refine`: the paper's kept set, then the fewest dropped views that link every
    kept view to the first) or flown (greedy, infogain, random: among the candidates linked to a flown
    view) only if it shares at least K verified matches with one kept or flown (nbv.sfm.links); 0: off,
    the paper's rule and the planners as before, bit-for-bit."""
    link_neighbours: int = 8
    """With --min-matches: a view is matched only with this many views nearest it by camera centre (the
    pairs of the match graph; keeps the matching cheap)."""

    def __post_init__(self) -> None:
        if self.min_matches < 0:
            raise ValueError(f"min_matches must be >= 0 (0: off), got {self.min_matches}")
        if self.link_neighbours < 1:
            raise ValueError(f"link_neighbours must be >= 1, got {self.link_neighbours}")

    @property
    def on(self) -> bool:
        """Whether the constraint applies (K > 0)."""
        return self.min_matches > 0


@dataclass(frozen=True, kw_only=True)
class SfmOption:
    """Whether a command that captures view sets (`nbv plan`, the planner studies, the demo) also runs
    structure from motion on them, and how: one flag name everywhere (--sfm)."""

    sfm: bool = False
    """Also run COLMAP's structure from motion on the captured views (`nbv sfm`): a plan's out/sfm/ (models,
    sfm.json) and the registration and pose errors in plan.json's `sfm`, beside coverage; the studies'
    tables gain the registered views, models and camera-centre error."""
    sfm_settings: SfmSettings = SfmSettings()
    """How COLMAP reconstructs the views (with --sfm)."""


@dataclass(frozen=True, kw_only=True)
class SfmConfig:
    """Settings of `nbv sfm`: COLMAP's structure from motion on a view dataset, scored against its poses."""

    dataset: Annotated[Path, Positional, arg(metavar="DATASET")]
    """A view dataset folder (transforms.json, images/), e.g. from `nbv scan`."""
    out: Path
    """Output folder, written atomically: images/ (links), sparse/0/ (the largest model; others
    sparse/1, ...) and sfm.json."""
    sfm: SfmSettings = SfmSettings()
    """How COLMAP reconstructs."""
    seed: int = 0
    """Seed of COLMAP's random sampling and of the GNSS noise."""
    overwrite: bool = False
    """Replace an existing non-empty output folder (only once the new result is complete)."""
