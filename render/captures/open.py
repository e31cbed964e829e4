"""Which dataset a folder holds (ours, a COLMAP model, a nerfstudio capture), read and written back alike.

A folder is our dataset when its `transforms.json` has our `nbv` block; a nerfstudio capture when it
has a `transforms.json` without one; a COLMAP capture when it holds `sparse/0/`, `sparse/` or the
model files themselves (`render.captures.colmap_capture.find_colmap`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from render.captures.colmap_capture import find_colmap, read_colmap_capture, write_colmap_subset
from render.captures.dataset import CaptureDataset, no_depth_message
from render.captures.frame import CaptureFrameConfig
from render.captures.nerfstudio import read_nerfstudio_capture, write_nerfstudio_subset
from render.dataset import ViewDataset, read_dataset, write_subset
from render.dataset_read import DatasetError, read_document


def capture_kind(path: str | Path) -> str | None:
    """"colmap" or "nerfstudio" for a capture from another tool at `path`; None for ours (or nothing)."""
    root = Path(path)
    doc_path = root / "transforms.json"
    if doc_path.is_file():
        return None if "nbv" in read_document(doc_path) else "nerfstudio"
    return "colmap" if root.is_dir() and find_colmap(root) is not None else None


def read_views(path: str | Path, config: CaptureFrameConfig = CaptureFrameConfig()) -> ViewDataset:
    """The dataset at `path`: ours as `read_dataset` reads it, or a COLMAP or nerfstudio capture."""
    root = Path(path)
    kind = capture_kind(root)
    if kind == "nerfstudio":
        return read_nerfstudio_capture(root, read_document(root / "transforms.json"), config)
    if kind == "colmap":
        return read_colmap_capture(root, config)
    if not (root / "transforms.json").exists() and root.is_dir():
        raise DatasetError(f"{root}: neither a view dataset (transforms.json) nor a COLMAP model (sparse/0/ "
                           f"with cameras, images, points3D beside images/)")
    return read_dataset(root)


def write_kept(dataset: ViewDataset, indices: list[int], out: str | Path, meta: dict[str, Any],
               overwrite: bool = False, extra: dict[str, Any] | None = None) -> None:
    """The frames `indices` written at `out` in the dataset's own format; `meta` (our `nbv` fields) goes
    into our datasets only, `extra` documents (refine.json) into every output folder."""
    if not isinstance(dataset, CaptureDataset):
        write_subset(dataset, indices, out, meta, overwrite, extra)
    elif dataset.kind == "colmap":
        write_colmap_subset(dataset, indices, Path(out), overwrite, extra or {})
    else:
        write_nerfstudio_subset(dataset, indices, Path(out), overwrite, extra or {})


def require_depth(path: str | Path) -> None:
    """Refuse (`DatasetError`) a capture from another tool where a command needs depth maps."""
    kind = capture_kind(path)
    if kind is not None:
        raise DatasetError(no_depth_message(Path(path), kind))


def refuse_folder(path: str | Path | None, name: str) -> None:
    """Refuse (`DatasetError`) a dataset folder given where a surface file is needed (`name`: the flag)."""
    if path is None or not Path(path).is_dir():
        return
    root = Path(path)
    if capture_kind(root) is not None:
        raise DatasetError(no_depth_message(root, capture_kind(root)))
    raise DatasetError(f"{name} {root} is a folder; give a mesh or point-cloud file (for a view dataset: "
                       f"`nbv reconstruct {root} --out DIR`, then DIR/mesh.ply)")
