"""`nbv scene list`, `nbv scene export SCENE --out DIR` and `nbv scene gallery --out FILE.png`.

`list` imports only the scene names (no mesh, texture or render code), so it starts at once.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

ACTIONS = {
    "list": "print the built-in scene names",
    "export": "write OUT/mesh.ply, the normalised target mesh (as rendered, no ground)",
    "gallery": "render each scene from four sides onto one PNG sheet",
}
"""The actions of `nbv scene` and their one-line help."""


def usage(prog: str) -> str:
    """The help of `nbv scene`: its actions."""
    lines = [f"usage: {prog} {{{','.join(ACTIONS)}}} [OPTIONS]", "", "actions:"]
    lines += [f"  {name:<8} {text}" for name, text in ACTIONS.items()]
    lines += ["", f"`{prog} ACTION --help` lists an action's options."]
    return "\n".join(lines)


def main(args: Sequence[str], prog: str) -> int:
    """Dispatch on the action (the first argument) and run it."""
    args = list(args)
    if not args or args[0] in ("-h", "--help"):
        print(usage(prog), file=sys.stdout if args else sys.stderr)
        return 0 if args else 2
    action, rest = args[0], args[1:]
    if action == "list":
        from scenes.catalog import list_scenes

        print("\n".join(list_scenes()))
        return 0
    if action == "export":
        from nbv.cli.parse import parse
        from scenes.export import ExportConfig, export_scene

        print(export_scene(parse(ExportConfig, rest, f"{prog} export")))
        return 0
    if action == "gallery":
        from nbv.cli.parse import parse
        from render.gallery import GalleryConfig, render_gallery

        print(render_gallery(parse(GalleryConfig, rest, f"{prog} gallery")))
        return 0
    raise ValueError(f"unknown action {action!r} (choose from {', '.join(ACTIONS)})")
