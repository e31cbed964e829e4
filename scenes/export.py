"""`nbv scene export`: a target's normalised mesh, written to a folder.

Apart from the catalog so that the catalog imports no scene spec: a spec loads
itself through the catalog (`SceneSpec.load`), and an import back would close a
circle.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from common.io import atomic_folder, check_output_folder
from scenes.spec import SceneSpec


@dataclass(frozen=True, kw_only=True)
class ExportConfig(SceneSpec):
    """Settings of `nbv scene export`: a target and the folder for its mesh."""

    out: Path
    """Output folder for mesh.ply."""
    overwrite: bool = False
    """Replace an existing OUT/mesh.ply."""


def export_scene(config: ExportConfig) -> Path:
    """Write the normalised target mesh (exactly as rendered, no ground) to `out/mesh.ply`, atomically
    (other files in `out` are kept)."""
    out = Path(config.out)
    check_output_folder(out, config.overwrite, ("mesh.ply",))
    mesh = config.load().target_mesh()
    with atomic_folder(out, config.overwrite, ("mesh.ply",)) as folder:
        mesh.export(folder / "mesh.ply", file_type="ply")
    return out / "mesh.ply"
