"""A native scan re-expressed as other tools write it (pycolmap's COLMAP models, nerfstudio JPEG captures),
in a random similarity frame, with optional lens distortion and an off-centre principal point."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pycolmap
from PIL import Image
from scipy.spatial.transform import Rotation

from render.dataset import ViewDataset
from render.viewpoint import opencv_to_opengl


def similarity(seed: int) -> tuple[np.ndarray, np.ndarray, float]:
    """A random rotation, translation and scale (x -> s R x + t)."""
    rng = np.random.default_rng(seed)
    rot = Rotation.random(random_state=seed).as_matrix()
    return rot, rng.uniform(-50, 50, 3), float(rng.uniform(0.1, 20))


def moved(c2w: np.ndarray, sim: tuple[np.ndarray, np.ndarray, float]) -> np.ndarray:
    """An OpenCV camera-to-world carried by the similarity `sim`."""
    rot, t, s = sim
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rot @ c2w[:3, :3], s * rot @ c2w[:3, 3] + t
    return out


def distorted(image: np.ndarray, K: np.ndarray, coeffs: tuple[float, ...]) -> np.ndarray:  # noqa: N803
    """The image a lens with OpenCV `coeffs` would take of the pinhole view `image` (same K)."""
    h, w = image.shape[:2]
    u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
    points = np.stack([u.ravel(), v.ravel()], -1)[:, None, :]
    ideal = cv2.undistortPoints(points, K, np.array(coeffs), P=K).reshape(h, w, 2).astype(np.float32)
    return cv2.remap(image, ideal[..., 0], ideal[..., 1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


def write_colmap(dataset: ViewDataset, root: Path, kind: str, sim, coeffs=(0.0, 0.0, 0.0, 0.0),
                 points: int = 40) -> Path:
    """ROOT/images (PNG) and ROOT/sparse/0 written by pycolmap: one OPENCV camera, image ids in reverse
    frame order (the reader orders by name), `points` 3D points seen by 2-3 images each."""
    (root / "images").mkdir(parents=True)
    (root / "sparse" / "0").mkdir(parents=True)
    k = dataset.camera.K
    rec = pycolmap.Reconstruction()
    rec.add_camera_with_trivial_rig(pycolmap.Camera(
        model="OPENCV", width=dataset.camera.width, height=dataset.camera.height, camera_id=1,
        params=[k[0, 0], k[1, 1], k[0, 2] + 0.5, k[1, 2] + 0.5, *coeffs]))
    rng = np.random.default_rng(0)
    n = len(dataset)
    for i, frame in enumerate(dataset.frames):
        name = f"{i:04d}.png"
        Image.fromarray(distorted(dataset.rgb(i), k, coeffs)).save(root / "images" / name)
        c2w = moved(frame.c2w, sim)
        w2c = np.linalg.inv(c2w)[:3]
        keypoints = rng.uniform(0, [dataset.camera.width, dataset.camera.height], (points, 2))
        rec.add_image_with_trivial_frame(pycolmap.Image(name=name, keypoints=keypoints, camera_id=1,
                                                        image_id=n - i), pycolmap.Rigid3d(w2c))
    for p in range(points):
        ids = rng.choice(n, size=int(rng.integers(2, 4)), replace=False)
        track = pycolmap.Track([pycolmap.TrackElement(int(n - i), p) for i in ids])
        rec.add_point3D(rng.normal(size=3), track, np.array([10, 20, 30], np.uint8))
    getattr(rec, f"write_{kind}")(root / "sparse" / "0")
    return root


def write_nerfstudio(dataset: ViewDataset, root: Path, sim, coeffs=(0.0, 0.0, 0.0, 0.0),
                     crop: tuple[int, int, int, int] = (0, 0, 0, 0), per_frame: bool = False,
                     suffix: str = "jpg") -> Path:
    """ROOT/transforms.json and ROOT/images/*.jpg (JPEG quality 95; or .png): OPENCV camera, no depth;
    `crop` (left, top, right, bottom pixels) moves the principal point off centre; `per_frame` puts the
    intrinsics in every frame (Polycam's layout)."""
    (root / "images").mkdir(parents=True)
    k = dataset.camera.K
    left, top, right, bottom = crop
    w, h = dataset.camera.width - left - right, dataset.camera.height - top - bottom
    camera = {"camera_model": "OPENCV", "fl_x": k[0, 0], "fl_y": k[1, 1], "cx": k[0, 2] - left + 0.5,
              "cy": k[1, 2] - top + 0.5, "w": w, "h": h, "k1": coeffs[0], "k2": coeffs[1],
              "p1": coeffs[2], "p2": coeffs[3]}
    crop_k = np.array([[k[0, 0], 0, k[0, 2] - left], [0, k[1, 1], k[1, 2] - top], [0, 0, 1]])
    frames = []
    for i, frame in enumerate(dataset.frames):
        name = f"images/frame_{i + 1:05d}.{suffix}"
        view = dataset.rgb(i)[top:dataset.camera.height - bottom, left:dataset.camera.width - right]
        image = Image.fromarray(distorted(np.ascontiguousarray(view), crop_k, coeffs))
        image.save(root / name, **({"quality": 95} if suffix == "jpg" else {}))
        entry = {"file_path": name, "transform_matrix": opencv_to_opengl(moved(frame.c2w, sim)).tolist()}
        frames.append({**entry, **camera} if per_frame else entry)
    doc = {**({} if per_frame else camera), "frames": frames,
           "applied_transform": [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, -1, 0]]}
    (root / "transforms.json").write_text(json.dumps(doc))
    return root
