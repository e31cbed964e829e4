"""`nbv reconstruct DATASET --out DIR`: TSDF fusion of a view dataset into DIR/mesh.ply and DIR/points.ply."""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from nbv.cli.config_args import add_config_arguments, config_from_args, positional
from nbv.recon import ReconstructionConfig, reconstruct_dataset, save_reconstruction
from render.dataset import read_dataset, write_json


@dataclass(frozen=True)
class ReconstructCommand:
    """What `nbv reconstruct` reads and writes."""

    dataset: Path = positional()
    """A view dataset folder (transforms.json, images/, depth/), e.g. from `nbv scan`."""
    out: Path = field(default=None)
    """Folder for mesh.ply, points.ply and reconstruction.json."""
    overwrite: bool = False
    """Replace mesh.ply, points.ply and reconstruction.json if the folder already holds them."""


OUTPUTS = ("mesh.ply", "points.ply", "reconstruction.json")
"""Files `nbv reconstruct` writes into its output folder."""


def reconstruct(command: ReconstructCommand, config: ReconstructionConfig) -> dict:
    """Fuse the dataset, write the outputs and return the run summary written to reconstruction.json."""
    existing = [name for name in OUTPUTS if (command.out / name).exists()]
    if existing and not command.overwrite:
        raise FileExistsError(f"{command.out} already holds {', '.join(existing)} (use --overwrite)")
    dataset = read_dataset(command.dataset)
    start = time.perf_counter()
    recon = reconstruct_dataset(dataset, config)
    seconds = time.perf_counter() - start
    mesh_path, points_path = save_reconstruction(recon, command.out)
    summary = {"dataset": str(command.dataset), "views": recon.n_views, "seconds": round(seconds, 3),
               "mesh": str(mesh_path), "points": str(points_path),
               "vertices": len(recon.mesh.vertices), "faces": len(recon.mesh.faces),
               "n_points": len(recon.points.vertices), "config": asdict(config)}
    write_json(command.out / "reconstruction.json", summary)
    return summary


def _run(args: argparse.Namespace) -> int:
    summary = reconstruct(config_from_args(ReconstructCommand, args),
                          config_from_args(ReconstructionConfig, args))
    print(f"{summary['views']} views fused in {summary['seconds']:.1f} s: {summary['mesh']} "
          f"({summary['faces']} faces), {summary['points']} ({summary['n_points']} points)")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `reconstruct` sub-command."""
    p = subparsers.add_parser("reconstruct", help="TSDF-fuse a view dataset into a mesh and a point cloud")
    add_config_arguments(p, ReconstructCommand)
    add_config_arguments(p, ReconstructionConfig)
    p.set_defaults(func=_run)
