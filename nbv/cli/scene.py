"""`nbv scene list` and `nbv scene export SCENE --out DIR`."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from scenes import list_scenes, load_scene


def export_scene(name: str, out: Path) -> Path:
    """Write the normalised target mesh (exactly as rendered, no ground) to `out/mesh.ply`."""
    mesh = load_scene(name).target_mesh()
    out.mkdir(parents=True, exist_ok=True)
    path = out / "mesh.ply"
    tmp = out / f".mesh.ply.tmp-{os.getpid()}"
    mesh.export(tmp, file_type="ply")
    tmp.replace(path)
    return path


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `scene` sub-command with its `list` and `export` actions."""
    p = subparsers.add_parser("scene", help="list built-in scenes or export a target mesh")
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    actions.add_parser("list", help="print the built-in scene names").set_defaults(
        func=lambda args: print("\n".join(list_scenes())))
    export = actions.add_parser("export", help="write OUT/mesh.ply, the normalised target mesh")
    export.add_argument("scene", metavar="SCENE", help="built-in scene name or mesh file path")
    export.add_argument("--out", type=Path, required=True, help="output folder")
    export.set_defaults(func=lambda args: print(export_scene(args.scene, args.out)))
