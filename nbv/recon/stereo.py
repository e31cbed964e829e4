"""Depth from two calibrated views by plane sweep: what a camera-only UAV measures (`lookahead-stereo`).

Plane-sweep stereo (Collins, CVPR 1996; Gallup et al., CVPR 2007): for every pixel of the reference image
and each of D fronto-parallel depth hypotheses, spaced evenly in inverse depth between `near` and `far`,
the point the pixel would see at that depth is projected into the source image and sampled there; the
hypothesis whose square window correlates best (zero-mean normalised cross-correlation, NCC) wins, refined
between hypotheses by a parabola through the best and its two neighbours. A pixel keeps its depth only
where its window has texture, the best correlation reaches `min_correlation`, the winner is not at either
end of the sweep, and the source's own sweep, projected back, agrees within `consistency` (a left-right
check, which removes occlusions and most false matches of repeated texture). Every other pixel is NaN:
not measured, which `OccupancyGrid.integrate` skips (neither carved nor marked), unlike depth 0 (no hit).

Images are grayscale floats in [0, 1]; depth is z-depth in metres (docs/conventions.md); poses are OpenCV
camera-to-world (x right, y down, z forward); both views share the intrinsics K. Torch, on the CPU.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F  # noqa: N812

from render.camera import pixel_rays
from render.viewpoint import validate_pose


@dataclass(frozen=True)
class StereoConfig:
    """Plane-sweep settings, chosen on four training buildings (`scripts/stereo_depth_eval.py`, round 25: the
    most pixels measured, 67 % of the target's, with at most 5 % of them more than 5 % off)."""

    hypotheses: int = 96
    """Depth hypotheses between near and far, evenly spaced in inverse depth."""
    window: int = 9
    """Side of the square correlation window, pixels (odd)."""
    min_correlation: float = 0.6
    """Least NCC of the best hypothesis for a pixel to keep its depth."""
    min_texture: float = 0.02
    """Least standard deviation of intensity (0 to 1) in a window, in the reference and the sampled source,
    for the window to be matched at all (the uniform sky and blank images have none)."""
    consistency: float = 0.02
    """Largest relative disagreement between the two views' depths of one point (the left-right check)."""

    def __post_init__(self) -> None:
        if self.hypotheses < 3 or self.window < 1 or self.window % 2 == 0:
            raise ValueError(f"stereo needs >= 3 hypotheses and an odd window, got {self.hypotheses}, "
                             f"{self.window}")
        if not (-1 <= self.min_correlation <= 1 and self.min_texture >= 0 and self.consistency > 0):
            raise ValueError(f"stereo needs min_correlation in [-1, 1], min_texture >= 0 and consistency "
                             f"> 0, got {self.min_correlation}, {self.min_texture}, {self.consistency}")


def grayscale(rgb: np.ndarray) -> np.ndarray:
    """(H, W) float32 luminance in [0, 1] (Rec. 601 weights) of an sRGB uint8 image (H, W, 3)."""
    return (np.asarray(rgb, np.float32)[..., :3] @ np.array([0.299, 0.587, 0.114], np.float32)) / 255.0


def box_depth_range(lower: np.ndarray, upper: np.ndarray, c2w: np.ndarray) -> tuple[float, float]:
    """The least and greatest z-depth of an axis-aligned box's corners from a camera at `c2w` (near clipped
    to 5 cm): the depths between which a surface inside the box can lie."""
    corners = np.array([[x, y, z] for x in (lower[0], upper[0]) for y in (lower[1], upper[1])
                        for z in (lower[2], upper[2])], np.float64)
    pose = validate_pose(c2w)
    z = (corners - pose[:3, 3]) @ pose[:3, 2]
    return max(float(z.min()), 0.05), max(float(z.max()), 0.1)


def _window_mean(x: torch.Tensor, window: int) -> torch.Tensor:
    """Mean of (N, H, W) images over square windows (the window shrinks at the border): a row pass, then a
    column pass (separable, so 2 x `window` reads a pixel instead of `window` squared)."""
    half = window // 2
    rows = F.avg_pool2d(x[:, None], (1, window), 1, (0, half), count_include_pad=False)
    return F.avg_pool2d(rows, (window, 1), 1, (half, 0), count_include_pad=False)[:, 0]


def _window_stats(x: torch.Tensor, window: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Mean and variance of (N, H, W) images over square windows."""
    mean = _window_mean(x, window)
    return mean, (_window_mean(x * x, window) - mean * mean).clamp(min=0.0)


def _project(depth: torch.Tensor, K: np.ndarray, ref_c2w: np.ndarray,  # noqa: N803
             src_c2w: np.ndarray, width: int, height: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Where the reference pixels at z-depths `depth` (..., H, W) land in the source: pixel (u, v) and
    z-depth, (..., H, W, 2) and (..., H, W)."""
    relative = np.linalg.inv(validate_pose(src_c2w)) @ validate_pose(ref_c2w)
    k = np.asarray(K, np.float64)
    # K (d R r + t) = d (K R r) + K t: one (H, W, 3) product, then a multiply-add per depth; K's last row
    # (0, 0, 1) leaves the third coordinate the z-depth.
    rays = torch.as_tensor(pixel_rays(k, width, height) @ (k @ relative[:3, :3]).T, dtype=torch.float32)
    offset = torch.as_tensor(k @ relative[:3, 3], dtype=torch.float32)
    pixels = depth[..., None] * rays + offset
    z = pixels[..., 2]
    return pixels[..., :2] / z.clamp(min=1e-9)[..., None], z


def _sample(image: torch.Tensor, uv: torch.Tensor) -> torch.Tensor:
    """Bilinear samples of an (H, W) image at pixel coordinates uv (N, H, W, 2), pixel centres at integers."""
    height, width = image.shape
    scale = torch.tensor([2.0 / width, 2.0 / height])
    grid = (uv + 0.5) * scale - 1.0
    return F.grid_sample(image.expand(len(uv), 1, height, width), grid, align_corners=False,
                         padding_mode="border")[:, 0]


def sweep(ref: np.ndarray, src: np.ndarray, K: np.ndarray, ref_c2w: np.ndarray,  # noqa: N803
          src_c2w: np.ndarray, near: float, far: float,
          config: StereoConfig = StereoConfig()) -> tuple[np.ndarray, np.ndarray]:
    """Per reference pixel, the refined best z-depth of the sweep and its NCC ((H, W) each; NaN and -1
    where no hypothesis could be matched or the best lies at an end of the sweep)."""
    if not 0 < near < far:
        raise ValueError(f"plane sweep needs 0 < near < far, got {near}, {far}")
    reference, source = (torch.as_tensor(np.asarray(x, np.float32)) for x in (ref, src))
    height, width = reference.shape
    inverse = torch.linspace(1.0 / near, 1.0 / far, config.hypotheses)
    uv, z = _project(1.0 / inverse[:, None, None].expand(-1, height, width), K, ref_c2w, src_c2w, width,
                     height)
    warped = _sample(source, uv)
    ref_mean, ref_var = _window_stats(reference[None], config.window)
    src_mean, src_var = _window_stats(warped, config.window)
    cross = _window_mean(reference[None] * warped, config.window) - ref_mean * src_mean
    ncc = cross / torch.sqrt((ref_var * src_var).clamp(min=1e-12))
    inside = (z > 0) & (uv[..., 0] >= 0) & (uv[..., 0] <= width - 1) & (uv[..., 1] >= 0) & \
        (uv[..., 1] <= height - 1)
    textured = (ref_var >= config.min_texture ** 2) & (src_var >= config.min_texture ** 2)
    ncc = torch.where(inside & textured, ncc, torch.tensor(-1.0))
    best, index = ncc.max(dim=0)
    interior = (index > 0) & (index < config.hypotheses - 1) & (best > -1)
    lower, upper = (ncc.gather(0, (index + k).clamp(0, config.hypotheses - 1)[None])[0] for k in (-1, 1))
    curvature = lower - 2 * best + upper
    offset = torch.where(curvature < 0, 0.5 * (lower - upper) / curvature.clamp(max=-1e-9),
                         torch.tensor(0.0)).clamp(-0.5, 0.5)
    step = inverse[1] - inverse[0]
    depth = 1.0 / (inverse[index] + offset * step)
    depth = torch.where(interior, depth, torch.tensor(float("nan")))
    return depth.numpy(), torch.where(interior, best, torch.tensor(-1.0)).numpy()


def _consistent(depth: np.ndarray, other: np.ndarray, K: np.ndarray, c2w: np.ndarray,  # noqa: N803
                other_c2w: np.ndarray, tolerance: float) -> np.ndarray:
    """Where `depth`'s points, projected into the other view, meet that view's depth within a relative
    `tolerance` (at the nearest pixel)."""
    height, width = depth.shape
    uv, z = _project(torch.as_tensor(np.nan_to_num(depth, nan=1.0), dtype=torch.float32), K, c2w, other_c2w,
                     width, height)
    u, v = (torch.round(uv[..., i]).long().numpy() for i in (0, 1))
    z = z.numpy()
    inside = np.isfinite(depth) & (z > 0) & (u >= 0) & (u < width) & (v >= 0) & (v < height)
    seen = np.full(depth.shape, np.nan, np.float32)
    seen[inside] = other[v[inside], u[inside]]
    with np.errstate(invalid="ignore"):
        return inside & (np.abs(seen - z) <= tolerance * z)


def two_view_depth(ref: np.ndarray, src: np.ndarray, K: np.ndarray, ref_c2w: np.ndarray,  # noqa: N803
                   src_c2w: np.ndarray, near: float, far: float,
                   config: StereoConfig = StereoConfig()) -> tuple[np.ndarray, np.ndarray]:
    """Both views' z-depth (H, W) float32 metres, NaN where not measured: each view swept against the
    other, kept where textured, correlated and consistent (module docstring)."""
    first, first_ncc = sweep(ref, src, K, ref_c2w, src_c2w, near, far, config)
    second, second_ncc = sweep(src, ref, K, src_c2w, ref_c2w, near, far, config)
    first = np.where(first_ncc >= config.min_correlation, first, np.nan).astype(np.float32)
    second = np.where(second_ncc >= config.min_correlation, second, np.nan).astype(np.float32)
    keep_first = _consistent(first, second, K, ref_c2w, src_c2w, config.consistency)
    keep_second = _consistent(second, first, K, src_c2w, ref_c2w, config.consistency)
    return np.where(keep_first, first, np.nan), np.where(keep_second, second, np.nan)


def box_stereo_depth(ref: np.ndarray, src: np.ndarray, K: np.ndarray, ref_c2w: np.ndarray,  # noqa: N803
                     src_c2w: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                     config: StereoConfig = StereoConfig()) -> tuple[np.ndarray, np.ndarray]:
    """`two_view_depth` swept between the nearest and farthest depths of the box `lower`-`upper` from either
    view (the surfaces a target's box can hold)."""
    ranges = [box_depth_range(lower, upper, pose) for pose in (ref_c2w, src_c2w)]
    near, far = min(r[0] for r in ranges), max(r[1] for r in ranges)
    return two_view_depth(ref, src, K, ref_c2w, src_c2w, near, far, config)


def within_box(depth: np.ndarray, K: np.ndarray, c2w: np.ndarray, lower: np.ndarray,  # noqa: N803
               upper: np.ndarray, tolerance: float = 0.0) -> np.ndarray:
    """`depth` (H, W) NaN where its point lies outside the box `lower`-`upper` grown by `tolerance` metres on
    every side: a target's surface cannot be there, and stereo's false matches beside a silhouette, the
    background taking the building's depth, mostly land there (round 51)."""
    pose = validate_pose(c2w)
    height, width = depth.shape
    points = (pixel_rays(np.asarray(K, np.float64), width, height) * np.nan_to_num(depth)[..., None]) \
        @ pose[:3, :3].T + pose[:3, 3]
    inside = np.all((points >= np.asarray(lower) - tolerance) & (points <= np.asarray(upper) + tolerance), -1)
    return np.where(inside, depth, np.nan).astype(np.float32)


def agreed_depth(depths: list[np.ndarray], tolerance: float, least: int = 2) -> np.ndarray:
    """One view's depth from several pairs' (each (H, W), NaN where that pair measured nothing): per pixel,
    the mean of the largest group of pairs within a relative `tolerance` of one of them, kept where that
    group has at least `least` pairs (NaN elsewhere). With two or more, a depth that only one pair's false
    match gives is dropped."""
    stack = np.stack([np.asarray(d, np.float32) for d in depths])
    with np.errstate(invalid="ignore"):
        near = np.abs(stack[:, None] - stack[None]) <= tolerance * stack[:, None]  # (anchor, pair, H, W)
    counts = near.sum(axis=1)
    anchor = counts.argmax(axis=0)
    group = np.take_along_axis(near, anchor[None, None], axis=0)[0]
    mean = np.where(group, stack, 0.0).sum(axis=0) / np.maximum(group.sum(axis=0), 1)
    return np.where(group.sum(axis=0) >= least, mean, np.nan).astype(np.float32)
