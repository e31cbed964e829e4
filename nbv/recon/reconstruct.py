"""`nbv reconstruct`: TSDF fusion of a view dataset into OUT/mesh.ply, OUT/points.ply and a run summary.

The three files are written together: into a temporary folder beside OUT, swapped into place in one
rename (other files in OUT are kept), so an interrupted run leaves OUT as it was.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

from tyro.conf import Positional, arg

from common.io import atomic_folder, check_output_folder, check_separate, write_json
from common.provenance import run_record
from nbv.recon.config import ReconstructionConfig
from nbv.recon.tsdf import reconstruct_dataset, save_reconstruction
from render.captures.open import require_depth
from render.dataset import read_dataset

OUTPUTS = ("mesh.ply", "points.ply", "reconstruction.json")
"""Files `nbv reconstruct` writes into its output folder."""


@dataclass(frozen=True, kw_only=True)
class ReconstructConfig:
    """Settings of `nbv reconstruct`: the dataset, the fusion settings, the output folder."""

    dataset: Annotated[Path, Positional, arg(metavar="DATASET")]
    """A view dataset folder (transforms.json, images/, depth/), e.g. from `nbv scan`."""
    out: Path
    """Folder for mesh.ply, points.ply and reconstruction.json."""
    recon: ReconstructionConfig = ReconstructionConfig()
    """TSDF fusion settings."""
    overwrite: bool = False
    """Replace mesh.ply, points.ply and reconstruction.json if the folder already holds them."""

    def __post_init__(self) -> None:
        check_separate(self.out, self.dataset, may_hold=True)  # other files in OUT are kept


def reconstruct(config: ReconstructConfig) -> dict[str, Any]:
    """Fuse the dataset, write the outputs and return the run summary written to reconstruction.json."""
    out = Path(config.out)
    check_output_folder(out, config.overwrite, OUTPUTS)
    require_depth(config.dataset)
    dataset = read_dataset(config.dataset)
    start = time.perf_counter()
    recon = reconstruct_dataset(dataset, config.recon)
    seconds = time.perf_counter() - start
    summary = {"dataset": str(config.dataset), "views": recon.n_views, "seconds": round(seconds, 3),
               "mesh": str(out / "mesh.ply"), "points": str(out / "points.ply"),
               "vertices": len(recon.mesh.vertices), "faces": len(recon.mesh.faces),
               "n_points": len(recon.points.vertices), **run_record("nbv reconstruct", config)}
    with atomic_folder(out, config.overwrite, OUTPUTS) as folder:
        save_reconstruction(recon, folder)
        write_json(folder / "reconstruction.json", summary)
    return summary
