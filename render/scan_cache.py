"""Reusable pipeline stages: scans that are rendered once and reused while nothing changed.

A scan folder records a key (scene content digest, camera, viewpoints, render
settings, variant) in its `nbv.scan_key`; `ensure_scan` re-renders only when
the stored key differs, so `make demo`, `make tables` and `nbv plan` can be
re-run cheaply and never reuse a stale scan.
"""

from __future__ import annotations

import atexit
import hashlib
import json
import shutil
import tempfile
import warnings
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

import numpy as np

from common.errors import describe
from common.io import cache_dir, in_cache
from common.locks import claim, release
from render.camera import UAVCamera
from render.capture import capture_dataset
from render.dataset import DatasetError, ViewDataset, read_dataset
from render.scan import HemispherePlan, hemisphere_scan, plan_record
from render.settings import RenderSettings
from render.variant import select_variant
from render.viewpoint import Viewpoint
from scenes.model import Scene


def scene_digest(scene: Scene) -> str:
    """A short content hash of a scene: geometry, materials and lighting."""
    h = hashlib.sha1()
    if scene.mitsuba_xml is not None:
        h.update(Path(scene.mitsuba_xml).read_bytes())
    for part in scene.parts:
        h.update(np.ascontiguousarray(part.vertices).tobytes())
        h.update(np.ascontiguousarray(part.faces).tobytes())
        h.update(repr((part.material, part.target)).encode())
    h.update(repr(scene.lighting).encode())
    return h.hexdigest()[:16]


def scan_key(scene: Scene, camera: UAVCamera, viewpoints: Sequence[Viewpoint], settings: RenderSettings,
             variant: str) -> dict:
    """Everything a rendered scan depends on, as a JSON-able dict."""
    views = hashlib.sha1(np.array([v.as_array() for v in viewpoints]).round(12).tobytes()).hexdigest()[:16]
    return {"scene": scene.name, "scene_digest": scene_digest(scene), "camera": asdict(camera),
            "viewpoints": views, "render": asdict(settings), "variant": variant}


def ensure_scan(scene: Scene, camera: UAVCamera, viewpoints: Sequence[Viewpoint], folder: str | Path,
                settings: RenderSettings = RenderSettings(), meta: dict | None = None, fresh: bool = False,
                progress: bool = True) -> ViewDataset:
    """The scan of `viewpoints` at `folder`, rendered now unless an identical one is already there.

    A run rendering the same folder is waited for (its scan is then reused); where the folder cannot be
    written (a full disk), a warning, and the scan is rendered into a temporary folder instead."""
    folder = Path(folder)
    key = scan_key(scene, camera, viewpoints, settings, select_variant(settings.variant).variant())
    meta, entry = {**(meta or {}), "scan_key": key}, folder
    try:
        claim(entry, wait=True)
        if fresh or _stored_key(folder) != json.loads(json.dumps(key)):
            capture_dataset(scene, camera, viewpoints, folder, settings, meta, overwrite=True,
                            progress=progress)
    except OSError as err:
        if not in_cache(entry):
            raise
        warnings.warn(f"scan cache {folder} not written ({describe(err)}); rendering into a temporary "
                      "folder instead", stacklevel=2)
        folder = Path(tempfile.mkdtemp(prefix="nbv-scan-")) / folder.name
        atexit.register(shutil.rmtree, folder.parent, True)
        capture_dataset(scene, camera, viewpoints, folder, settings, meta, overwrite=True, progress=progress)
    finally:
        release(entry)
    return read_dataset(folder)


def full_scan(scene: Scene, camera: UAVCamera, folder: str | Path | None = None,
              settings: RenderSettings = RenderSettings(), plan: HemispherePlan = HemispherePlan(),
              fresh: bool = False, progress: bool = True) -> ViewDataset:
    """The full-coverage hemisphere scan (288 views by default; paper Sec. V-B).

    Args:
        folder: where it lives; default: `$NBV_CACHE_DIR/scans/<scene>-<digest>`.
    """
    viewpoints = hemisphere_scan(camera, plan)
    if folder is None:
        safe = "".join(c if c.isalnum() or c in "_-" else "_" for c in scene.name)[:40]
        folder = cache_dir() / "scans" / f"{safe}-{scene_digest(scene)}-{camera.width}x{camera.height}"
    meta = {"plan": plan_record(plan, len(viewpoints))}
    return ensure_scan(scene, camera, viewpoints, folder, settings, meta, fresh, progress)


def _stored_key(folder: Path) -> dict | None:
    try:
        return read_dataset(folder).meta.get("scan_key")
    except DatasetError:
        return None
