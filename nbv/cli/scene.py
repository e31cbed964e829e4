"""`nbv scene list`, `nbv scene export SCENE --out DIR` and `nbv scene gallery --out FILE.png`."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from nbv.cli.config_args import add_config_arguments, config_from_args
from scenes import list_scenes, load_scene
from scenes.normalise import UP_AXES


def export_scene(name: str, out: Path, up_axis: str = "z") -> Path:
    """Write the normalised target mesh (exactly as rendered, no ground) to `out/mesh.ply`."""
    mesh = load_scene(name, up_axis).target_mesh()
    out.mkdir(parents=True, exist_ok=True)
    path = out / "mesh.ply"
    tmp = out / f".mesh.ply.tmp-{os.getpid()}"
    mesh.export(tmp, file_type="ply")
    tmp.replace(path)
    return path


def _gallery(args: argparse.Namespace) -> None:
    from nbv.gallery import GalleryConfig, render_gallery

    print(render_gallery(config_from_args(GalleryConfig, args)))


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `scene` sub-command with its `list`, `export` and `gallery` actions."""
    from nbv.gallery import GalleryConfig

    p = subparsers.add_parser("scene", help="list built-in scenes, export a target mesh, render a gallery")
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    actions.add_parser("list", help="print the built-in scene names").set_defaults(
        func=lambda args: print("\n".join(list_scenes()))
    )
    export = actions.add_parser("export", help="write OUT/mesh.ply, the normalised target mesh")
    export.add_argument(
        "scene", metavar="SCENE", help="built-in scene name, random:SEED, or a mesh / Mitsuba XML file path"
    )
    export.add_argument("--out", type=Path, required=True, help="output folder")
    export.add_argument("--up-axis", choices=UP_AXES, default="z", help="up axis of a mesh file (default: z)")
    export.set_defaults(func=lambda args: print(export_scene(args.scene, args.out, args.up_axis)))
    gallery = actions.add_parser("gallery", help="render each scene from four sides onto one PNG sheet")
    add_config_arguments(gallery, GalleryConfig)
    gallery.set_defaults(func=_gallery)
