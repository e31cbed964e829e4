"""COLMAP's structure from motion on a view dataset, through pycolmap on the CPU.

Stages (`run_sfm`): SIFT features into a database with the dataset's one PINHOLE camera (its known
intrinsics, COLMAP's convention: pixel centres at +0.5, so cx = transforms.json's `cx`); optional
position priors (GNSS: the true centres plus seeded noise); matching of every pair or of pose
neighbours; incremental mapping with the intrinsics held fixed (no focal length, principal point or
extra parameter is refined, in bundle adjustment or in pose estimation). Models come back largest first.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pycolmap

from nbv.fanout.worker import usable_cores
from nbv.sfm.config import SfmSettings
from render.camera import UAVCamera

QUIET_LOG_LEVEL = 3
"""glog's level below which COLMAP's messages are dropped when its log is off (3: fatal only)."""


@dataclass(frozen=True)
class SfmRun:
    """What COLMAP made of a view set."""

    models: tuple[pycolmap.Reconstruction, ...]
    """The reconstructions, most registered images first (empty: no model)."""
    seconds: dict[str, float]
    """Wall time of each stage: features, matching, mapping."""
    priors: dict[str, np.ndarray]
    """Image name -> the position prior written for it (empty without priors)."""


def colmap_threads(requested: int) -> int:
    """COLMAP's thread count: `requested` if positive, else the cores this process may use."""
    return requested if requested > 0 else usable_cores()


def pinhole_params(camera: UAVCamera) -> tuple[float, float, float, float]:
    """COLMAP PINHOLE fx, fy, cx, cy of the camera (pixel centres at +0.5, as render/colmap.py writes).

    Example:
        >>> pinhole_params(UAVCamera(36, 24, focal_mm=36.0))
        (36.0, 36.0, 18.0, 12.0)
    """
    k = camera.K
    return (float(k[0, 0]), float(k[1, 1]), float(k[0, 2]) + 0.5, float(k[1, 2]) + 0.5)


def extract(database: Path, images: Path, names: list[str], camera: UAVCamera, settings: SfmSettings,
            threads: int) -> None:
    """SIFT features of `names` under `images` into `database`, all sharing one PINHOLE camera."""
    reader = pycolmap.ImageReaderOptions(camera_model="PINHOLE",
                                         camera_params=",".join(map(repr, pinhole_params(camera))))
    options = pycolmap.FeatureExtractionOptions(num_threads=threads, use_gpu=False)
    options.sift.max_num_features = settings.sift_max_features
    pycolmap.extract_features(database, images, image_names=names, camera_mode=pycolmap.CameraMode.SINGLE,
                              reader_options=reader, extraction_options=options, device=pycolmap.Device.cpu)


def write_priors(database: Path, positions: dict[str, np.ndarray], sigma_m: float) -> None:
    """Position priors (Cartesian, isotropic covariance sigma_m^2) of the named images into `database`."""
    db = pycolmap.Database.open(database)
    try:
        for image in db.read_all_images():
            prior = pycolmap.PosePrior(corr_data_id=image.data_id, position=positions[image.name],
                                       position_covariance=np.eye(3) * sigma_m**2,
                                       coordinate_system=pycolmap.PosePriorCoordinateSystem.CARTESIAN)
            db.write_pose_prior(prior)
    finally:
        db.close()


def match(database: Path, settings: SfmSettings, threads: int) -> None:
    """Match and verify image pairs: all of them, or each image with its nearest by prior position."""
    options = pycolmap.FeatureMatchingOptions(num_threads=threads, use_gpu=False)
    if settings.matching == "exhaustive":
        pycolmap.match_exhaustive(database, matching_options=options, device=pycolmap.Device.cpu)
        return
    pairing = pycolmap.SpatialPairingOptions(ignore_z=False, max_num_neighbors=settings.spatial_neighbours,
                                             max_distance=1e9, num_threads=threads)
    pycolmap.match_spatial(database, matching_options=options, pairing_options=pairing,
                           device=pycolmap.Device.cpu)


def mapping_options(settings: SfmSettings, seed: int, threads: int) -> pycolmap.IncrementalPipelineOptions:
    """Incremental mapping with the intrinsics fixed, seeded, priors used where they were written."""
    options = pycolmap.IncrementalPipelineOptions(
        ba_refine_focal_length=False, ba_refine_principal_point=False, ba_refine_extra_params=False,
        num_threads=threads, random_seed=seed, use_prior_position=settings.gnss_noise_m is not None)
    options.mapper.abs_pose_refine_focal_length = False
    options.mapper.abs_pose_refine_extra_params = False
    return options


def gnss_positions(names: list[str], centres: np.ndarray, sigma_m: float, seed: int) -> dict[str, np.ndarray]:
    """Each image's true centre plus Gaussian noise of `sigma_m` per axis (0: exact), seeded."""
    noise = np.random.default_rng(seed).normal(0.0, sigma_m, size=centres.shape) if sigma_m else 0.0
    return dict(zip(names, np.asarray(centres, np.float64) + noise, strict=True))


def run_sfm(images: Path, names: list[str], camera: UAVCamera, centres: np.ndarray, settings: SfmSettings,
            seed: int, work: Path) -> SfmRun:
    """COLMAP on the images `names` under `images` (true centres `centres`, (N, 3), for priors and
    spatial pairs); the database and COLMAP's own output go under `work`."""
    threads = colmap_threads(settings.colmap_threads)
    pycolmap.logging.minloglevel = 0 if settings.colmap_log else QUIET_LOG_LEVEL
    pycolmap.set_random_seed(seed)
    database, seconds = work / "database.db", {}
    start = time.perf_counter()
    extract(database, images, names, camera, settings, threads)
    seconds["features"] = time.perf_counter() - start
    priors: dict[str, np.ndarray] = {}
    if settings.gnss_noise_m is not None or settings.matching == "spatial":
        priors = gnss_positions(names, centres, settings.gnss_noise_m or 0.0, seed)
        # without GNSS the exact centres only choose spatial pairs: mapping ignores priors (and their 1 m)
        write_priors(database, priors, settings.gnss_noise_m or 1.0)
    start = time.perf_counter()
    match(database, settings, threads)
    seconds["matching"] = time.perf_counter() - start
    start = time.perf_counter()
    (work / "colmap").mkdir(parents=True, exist_ok=True)
    found = pycolmap.incremental_mapping(database, images, work / "colmap",
                                         mapping_options(settings, seed, threads))
    seconds["mapping"] = time.perf_counter() - start
    models = sorted(found.values(), key=lambda m: (-m.num_reg_images(), -m.num_points3D()))
    return SfmRun(tuple(models), seconds, priors if settings.gnss_noise_m is not None else {})
