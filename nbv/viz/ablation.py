"""Pictures of `nbv ablate`: each metric against an axis's levels, quality against render time, crops."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from nbv.viz.figures import save_figure

CROP = 0.5
"""The image grid shows the central crop of this fraction of each view's width and height."""


def plot_axis(title: str, rows: Sequence[dict[str, Any]], metrics: Sequence[tuple[str, str, float, str]],
              out: str | Path) -> Path:
    """One panel per metric: its mean against the axis's levels, error bars one std, the reference in red."""
    shown = [m for m in metrics if any(r[f"{m[0]}_mean"] is not None for r in rows)]
    cols = 4
    fig = Figure(figsize=(3.4 * cols, 2.8 * math.ceil(len(shown) / cols)))
    axes = np.atleast_1d(fig.subplots(math.ceil(len(shown) / cols), cols)).ravel()
    x = np.arange(len(rows))
    labels = [r["level"] for r in rows]
    for ax, (key, name, _, _) in zip(axes, shown):
        mean = [math.nan if r[f"{key}_mean"] is None else r[f"{key}_mean"] for r in rows]
        std = [0.0 if r[f"{key}_std"] is None else r[f"{key}_std"] for r in rows]
        ax.errorbar(x, mean, yerr=std, marker="o", capsize=4, color="tab:blue")
        for i, r in enumerate(rows):
            if r["reference"]:
                ax.plot(x[i], mean[i], "o", color="tab:red", markersize=8, label="reference")
        ax.set_xticks(x, labels, rotation=25, ha="right", fontsize=8)
        ax.set_title(name, fontsize=10)
    for ax in axes[len(shown):]:
        ax.set_visible(False)
    fig.suptitle(f"{title} (mean ± std over buildings and seeds; red: reference)")
    return save_figure(fig, out)


def plot_quality_vs_time(rows: Sequence[dict[str, Any]], out: str | Path) -> Path:
    """PSNR and SIFT repeatability against render time per view for every level of every axis."""
    fig = Figure(figsize=(13, 5.5))
    axes = fig.subplots(1, 2)
    names = list(dict.fromkeys(r["axis"] for r in rows))
    colours = {name: f"C{i % 10}" for i, name in enumerate(names)}
    for ax, (key, label) in zip(axes, (("psnr_db", "PSNR dB vs reference"),
                                       ("repeatability", "SIFT repeatability vs reference"))):
        for name in names:
            mine = [r for r in rows if r["axis"] == name and r[f"{key}_mean"] is not None]
            ax.scatter([r["render_s_per_view_mean"] for r in mine], [r[f"{key}_mean"] for r in mine],
                       color=colours[name], label=name, s=22)
            for r in mine:
                ax.annotate(r["level"], (r["render_s_per_view_mean"], r[f"{key}_mean"]), fontsize=6,
                            xytext=(3, 2), textcoords="offset points")
        ax.set_xscale("log")
        ax.set(xlabel="render time per RGB-D view, s (log)", ylabel=label)
        ax.grid(alpha=0.3)
    axes[1].legend(fontsize=7, ncol=2)
    fig.suptitle("Quality against render time, every ablation level")
    return save_figure(fig, out)


def central_crop(image: np.ndarray, fraction: float = CROP) -> np.ndarray:
    """The centred `fraction` of `image`'s height and width (at least one pixel each)."""
    h, w = image.shape[:2]
    ch, cw = max(1, round(h * fraction)), max(1, round(w * fraction))
    top, left = (h - ch) // 2, (w - cw) // 2
    return image[top:top + ch, left:left + cw]


def plot_crops(grid: dict[str, Sequence[tuple[str, np.ndarray]]], out: str | Path) -> Path:
    """A grid of the same central crop: one row per axis, one column per level (label above)."""
    rows = [(name, images) for name, images in grid.items() if images]
    cols = max((len(images) for _, images in rows), default=1)
    fig = Figure(figsize=(2.4 * cols + 1.2, 2.0 * max(1, len(rows))))
    axes = np.array(fig.subplots(max(1, len(rows)), cols, squeeze=False))
    for ax in axes.ravel():
        ax.axis("off")
    for i, (name, images) in enumerate(rows):
        for j, (label, image) in enumerate(images):
            axes[i, j].imshow(central_crop(image), interpolation="nearest")
            axes[i, j].set_title(f"{name}: {label}", fontsize=7)
    fig.suptitle("The same crop at every level (first building, first seed)")
    return save_figure(fig, out)
