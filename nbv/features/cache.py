"""On-disk cache of a dataset's SIFT features, so sweeps and reruns extract once.

A cache file is keyed by the dataset's content (SHA-256 of every image file's
bytes, in frame order) and by the feature settings that change the result
(backend, max_features, contrast_threshold, double_image, library versions):
moving or renaming a dataset keeps its cache, editing one image invalidates it.
Files are written atomically and loaded with `weights_only=True`; a file that
does not load or does not match the dataset is rebuilt, never trusted.
"""

from __future__ import annotations

import hashlib
import io
import json
import warnings
from collections.abc import Callable
from pathlib import Path

import cv2
import kornia
import torch

from common.cache import write_cache
from common.io import cache_dir as cache_root
from nbv.features.sift import DESCRIPTOR_DIM, FeatureConfig, Features, extract_features
from render.dataset import ViewDataset
from render.dataset_read import image_bytes

CACHE_VERSION = 1


def default_cache_dir() -> Path:
    """`features/` under the project's cache root (`$NBV_CACHE_DIR`, else `~/.cache/nbv`)."""
    return cache_root() / "features"


def dataset_digest(dataset: ViewDataset) -> str:
    """SHA-256 over the bytes of the dataset's images, in frame order; each file is read through the
    reader's size check (`image_bytes`), so a huge file is refused before it is read."""
    digest = hashlib.sha256()
    width, height = dataset.camera.width, dataset.camera.height
    for frame in dataset.frames:
        digest.update(image_bytes(frame.rgb_path, width, height))
        if "undistort" in frame.meta:  # a capture's image is undistorted on reading: key its camera too
            digest.update(json.dumps(frame.meta["undistort"]).encode())
        digest.update(b"\0")
    return digest.hexdigest()


def cache_key(dataset: ViewDataset, config: FeatureConfig) -> str:
    """The cache file's stem: dataset content + result-changing settings."""
    settings = {"version": CACHE_VERSION, "backend": config.backend, "max_features": config.max_features,
                "contrast_threshold": config.contrast_threshold, "double_image": config.double_image,
                "lib": kornia.__version__ if config.backend == "kornia" else cv2.__version__}
    tag = hashlib.sha256(json.dumps(settings, sort_keys=True).encode()).hexdigest()[:16]
    return f"{dataset_digest(dataset)[:32]}-{config.backend}-{tag}"


def dataset_features(dataset: ViewDataset, config: FeatureConfig, cache_dir: str | Path | None = None,
                     progress: Callable[[int], None] | None = None) -> list[Features]:
    """Features of every frame of `dataset`, from the cache when a valid entry exists.

    Args:
        dataset: the views, in frame order.
        config: feature settings.
        cache_dir: folder of cache files (default `default_cache_dir()`).
        progress: called with the number of views just extracted (e.g. a tqdm `update`).

    Returns:
        One `Features` per frame, on `config.device`.

    Raises:
        ValueError: the dataset has no frames.
    """
    if len(dataset) == 0:
        raise ValueError(f"dataset {dataset.root} has no frames (no images to extract features from)")
    folder = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    path = folder / f"{cache_key(dataset, config)}.pt"
    if path.exists():
        try:
            return [f.to(config.device) for f in load_features(path, len(dataset))]
        except Exception as err:  # noqa: BLE001 - whatever fails to load is rebuilt, never trusted
            warnings.warn(f"feature cache {path} is corrupt ({err}); rebuilding it", stacklevel=2)
    feats: list[Features] = []
    for start in range(0, len(dataset), config.batch_size):
        stop = min(start + config.batch_size, len(dataset))
        feats.extend(extract_features([dataset.rgb(i) for i in range(start, stop)], config))
        if progress is not None:
            progress(stop - start)
    save_features(path, feats)
    return feats


def save_features(path: Path, feats: list[Features]) -> None:
    """Write features as one flat tensor per field plus per-view counts (atomic; a warning if it fails)."""
    doc = {
        "version": torch.tensor(CACHE_VERSION),
        "counts": torch.tensor([len(f) for f in feats], dtype=torch.long),
        "keypoints": torch.cat([f.keypoints.cpu() for f in feats]).float(),
        "descriptors": torch.cat([f.descriptors.cpu() for f in feats]).float(),
        "responses": torch.cat([f.responses.cpu() for f in feats]).float(),
    }
    buffer = io.BytesIO()  # saved in memory first: torch.save hides a full disk's errno in a RuntimeError
    torch.save(doc, buffer)
    write_cache(path, lambda tmp: tmp.write_bytes(buffer.getbuffer()))  # if it fails: a warning


def load_features(path: Path, views: int) -> list[Features]:
    """Read a cache file written by `save_features`, checking it holds `views` views.

    Raises:
        ValueError: the file is not a valid cache of `views` views.
    """
    doc = torch.load(path, map_location="cpu", weights_only=True)
    if not isinstance(doc, dict) or int(doc.get("version", -1)) != CACHE_VERSION:
        raise ValueError("not a feature cache of this version")
    counts, kp, desc, resp = doc["counts"], doc["keypoints"], doc["descriptors"], doc["responses"]
    total = int(counts.sum()) if counts.numel() else 0
    if (counts.shape != (views,) or bool((counts < 0).any()) or kp.shape != (total, 2)
            or desc.shape != (total, DESCRIPTOR_DIM) or resp.shape != (total,)):
        raise ValueError(f"shapes do not match a cache of {views} views")
    if not (torch.isfinite(desc).all() and torch.isfinite(kp).all()):
        raise ValueError("non-finite values")
    sizes = counts.tolist()
    return [Features(k, d, r) for k, d, r in zip(kp.split(sizes), desc.split(sizes), resp.split(sizes))]
