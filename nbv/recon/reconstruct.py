"""`nbv reconstruct`: TSDF fusion of a view dataset into OUT/mesh.ply, OUT/points.ply and a run summary."""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Annotated, Any

from tyro.conf import Positional, arg

from common.io import write_json
from nbv.recon.config import ReconstructionConfig
from nbv.recon.tsdf import reconstruct_dataset, save_reconstruction
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


def check_outputs(out: Path, names: tuple[str, ...], overwrite: bool) -> None:
    """Refuse (FileExistsError) when `out` already holds any of `names` and `overwrite` is off."""
    existing = [name for name in names if (out / name).exists()]
    if existing and not overwrite:
        raise FileExistsError(f"{out} already holds {', '.join(existing)} (use --overwrite)")


def reconstruct(config: ReconstructConfig) -> dict[str, Any]:
    """Fuse the dataset, write the outputs and return the run summary written to reconstruction.json."""
    out = Path(config.out)
    check_outputs(out, OUTPUTS, config.overwrite)
    dataset = read_dataset(config.dataset)
    start = time.perf_counter()
    recon = reconstruct_dataset(dataset, config.recon)
    seconds = time.perf_counter() - start
    mesh_path, points_path = save_reconstruction(recon, out)
    summary = {"dataset": str(config.dataset), "views": recon.n_views, "seconds": round(seconds, 3),
               "mesh": str(mesh_path), "points": str(points_path),
               "vertices": len(recon.mesh.vertices), "faces": len(recon.mesh.faces),
               "n_points": len(recon.points.vertices), "config": asdict(config.recon)}
    write_json(out / "reconstruction.json", summary)
    return summary
