"""SIFT features of views (paper Sec. III, step 1): keypoints, L2-normalised 128-d descriptors.

Two backends behind one interface: Kornia (the default; torch, batched over
views, any device) and OpenCV (for comparison). Both work on the sRGB-to-gray
image (ITU-R 601 weights, as `cv2.COLOR_RGB2GRAY` and `kornia.color.rgb_to_grayscale`),
return descriptors in OpenCV's SIFT layout, plain SIFT (not RootSIFT),
L2-normalised, so the Bag of Views' cosine is the descriptors' dot product.

The Kornia configuration is the fastest one found that is still SIFT (measured
in `nbv.bench.bov`): Kornia 0.9's `SIFTFeatureScaleSpace` with the `pyramid`
descriptor backend (DoG scale-space extrema, 3-D quadratic refinement,
orientation assignment, 4x4x8 gradient histograms, all sharing one Gaussian
pyramid). By default it starts at the input resolution rather than doubling the
image first (Lowe 2004 Sec. 3.3 doubles; VLFeat's default does not): the
doubled first octave holds 3/4 of the pyramid's pixels. Measured on 320x240
renders, one thread, CPU time per view: OpenCV 20 ms (85 keypoints), Kornia
47 ms (53 keypoints; the finest blobs need the doubled octave), Kornia with
doubling 199 ms (117 keypoints). `double_image=True` restores Lowe's octave -1.
Kornia's DoG detector has no contrast or edge rejection; we apply OpenCV's
contrast rule (|DoG| >= contrast_threshold / 3 on a [0, 1] image), so a flat or
noise-only view gives no keypoints with either backend. Edge rejection is not
applied on the Kornia path.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import cv2
import kornia.feature as KF
import numpy as np
import torch
from kornia.color import rgb_to_grayscale
from kornia.feature.sift.scale_space import _SIFTScalePyramid

from nbv.features.config import FeatureConfig

DESCRIPTOR_DIM = 128
"""Length of a SIFT descriptor."""
OCTAVE_LAYERS = 3
"""SIFT intervals per octave (Lowe 2004; OpenCV's and Kornia's default)."""


@dataclass(frozen=True)
class Features:
    """SIFT features of one view.

    Shape:
        - keypoints: :math:`(M, 2)` float32 pixel (x, y), pixel centres at integers (OpenCV's
          own keypoints sit ~0.25 px below-right of Kornia's on the same blob).
        - descriptors: :math:`(M, 128)` float32, rows L2-normalised.
        - responses: :math:`(M,)` float32 detector responses (|DoG|), descending.
    """

    keypoints: torch.Tensor
    descriptors: torch.Tensor
    responses: torch.Tensor

    def __len__(self) -> int:
        return int(self.keypoints.shape[0])

    def to(self, device: str | torch.device) -> Features:
        """The same features on `device`."""
        return Features(self.keypoints.to(device), self.descriptors.to(device), self.responses.to(device))

    @staticmethod
    def empty(device: str | torch.device = "cpu") -> Features:
        """A view with no keypoints (M = 0)."""
        return Features(torch.zeros(0, 2, device=device), torch.zeros(0, DESCRIPTOR_DIM, device=device),
                        torch.zeros(0, device=device))


def check_images(images: np.ndarray | Sequence[np.ndarray]) -> list[np.ndarray]:
    """Validate a batch of sRGB views and return it as a list of (H, W, 3) uint8 arrays.

    Raises:
        ValueError: naming the view and what is wrong with its shape or dtype.
    """
    if isinstance(images, np.ndarray):
        if images.ndim != 4:
            raise ValueError(f"images must be (B, H, W, 3) uint8 or a list of (H, W, 3) uint8, "
                             f"got an array of shape {images.shape}")
        images = list(images)
    views = []
    for i, img in enumerate(images):
        if not isinstance(img, np.ndarray):
            raise ValueError(f"image {i} must be a numpy array, got {type(img).__name__}")
        if img.ndim != 3 or img.shape[2] != 3 or min(img.shape[:2]) < 1:
            raise ValueError(f"image {i} must be (H, W, 3) sRGB, got shape {img.shape}")
        if img.dtype != np.uint8:
            raise ValueError(f"image {i} must be uint8 sRGB, got dtype {img.dtype}")
        views.append(img)
    return views


def extract_features(images: np.ndarray | Sequence[np.ndarray], config: FeatureConfig) -> list[Features]:
    """SIFT features of each view, on its sRGB-to-gray image.

    Args:
        images: sRGB views, a uint8 array (B, H, W, 3) or a list of (H, W, 3) uint8 arrays.
        config: backend and settings.

    Returns:
        One `Features` per view, tensors on `config.device`; a view without keypoints has M = 0.

    Shape:
        - images: :math:`(B, H, W, 3)` uint8.

    Example:
        >>> rng = np.random.default_rng(0)
        >>> img = np.repeat(rng.integers(0, 255, (64, 80, 1), dtype=np.uint8), 3, axis=2)
        >>> feats = extract_features([img], FeatureConfig(max_features=50))
        >>> feats[0].descriptors.shape[1], len(feats[0]) <= 50
        (128, True)
    """
    views = check_images(images)
    if config.backend == "opencv":
        return [opencv_sift(img, config) for img in views]
    out: list[Features] = []
    # Views of one size share a forward pass; sizes may differ across a list.
    start = 0
    while start < len(views):
        stop = start + 1
        while (stop < len(views) and stop - start < config.batch_size
               and views[stop].shape == views[start].shape):
            stop += 1
        out.extend(kornia_sift(np.stack(views[start:stop]), config))
        start = stop
    return out


def opencv_sift(image: np.ndarray, config: FeatureConfig) -> Features:
    """OpenCV SIFT of one (H, W, 3) uint8 sRGB view, descriptors L2-normalised."""
    gray = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    sift = cv2.SIFT_create(nfeatures=config.max_features, contrastThreshold=config.contrast_threshold)
    keypoints, desc = sift.detectAndCompute(gray, None)
    if not keypoints:
        return Features.empty(config.device)
    # nfeatures keeps ties at the cut, so OpenCV may return a few more: keep the strongest.
    responses = np.array([k.response for k in keypoints], dtype=np.float32)
    order = np.argsort(-responses, kind="stable")[: config.max_features]
    xy = np.array([k.pt for k in keypoints], dtype=np.float32)[order]
    desc = torch.from_numpy(desc[order].astype(np.float32))
    return Features(torch.from_numpy(xy).to(config.device),
                    torch.nn.functional.normalize(desc, dim=1).to(config.device),
                    torch.from_numpy(responses[order]).to(config.device))


class _InputResolutionPyramid(_SIFTScalePyramid):
    """Kornia's SIFT pyramid without the 2x upsampling: octave 0 is the input image.

    Kornia's detector and descriptor both place octave o at pixel size 0.5 * 2^o
    (the doubled image's); without doubling, every coordinate and scale they
    report is half the input's, which `kornia_sift` undoes.
    """

    def __init__(self) -> None:
        super().__init__()
        # The input's assumed blur is 0.5 px (Lowe 2004); blur it to 1.6 directly.
        self._sigmas[0] = math.sqrt(1.6**2 - 0.5**2)
        self._register_kernels(torch.device("cpu"))

    @staticmethod
    def _double(image: torch.Tensor) -> torch.Tensor:
        return image


@lru_cache(maxsize=8)
def _kornia_module(max_features: int, double_image: bool, device: str) -> KF.SIFTFeatureScaleSpace:
    module = KF.SIFTFeatureScaleSpace(max_features, rootsift=False, device=device,
                                      descriptor_backend="pyramid", descriptor_layout="opencv")
    if not double_image:
        module.detector.scale_pyr = _InputResolutionPyramid().to(device)
    return module.eval()


def kornia_sift(images: np.ndarray, config: FeatureConfig) -> list[Features]:
    """Kornia SIFT of a batch of same-size views in one forward pass.

    Args:
        images: sRGB views, uint8.
        config: settings (`backend` is ignored).

    Shape:
        - images: :math:`(B, H, W, 3)`.
    """
    module = _kornia_module(config.max_features, config.double_image, config.device)
    with torch.inference_mode():
        rgb = torch.from_numpy(np.ascontiguousarray(images)).to(config.device)
        gray = rgb_to_grayscale(rgb.permute(0, 3, 1, 2).float() / 255.0)
        lafs, responses, descs = module(gray)
        centres = KF.get_laf_center(lafs) * (1.0 if config.double_image else 2.0)
        keep = KF.laf_is_filled(lafs) & (responses >= config.contrast_threshold / OCTAVE_LAYERS)
        out = []
        for b in range(len(images)):
            k = keep[b]
            out.append(Features(centres[b, k].float().clone(),
                                torch.nn.functional.normalize(descs[b, k].float(), dim=1),
                                responses[b, k].float().clone()))
    return out
