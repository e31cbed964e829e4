"""Pictures people look at: a contact sheet of a dataset's views and the camera trajectory."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import trimesh  # noqa: E402
from PIL import Image, ImageDraw  # noqa: E402
from scipy.spatial import ConvexHull  # noqa: E402

from render.dataset import ViewDataset  # noqa: E402


def contact_sheet(dataset: ViewDataset, out: str | Path, max_views: int = 48, thumb_width: int = 160) -> Path:
    """Save a grid of (up to `max_views`, evenly picked) thumbnails, each labelled with its index."""
    if len(dataset) == 0:
        raise ValueError(f"dataset {dataset.root} has no views")
    picks = np.unique(np.linspace(0, len(dataset) - 1, min(max_views, len(dataset))).round().astype(int))
    thumb_h = round(thumb_width * dataset.camera.height / dataset.camera.width)
    cols = math.ceil(math.sqrt(len(picks) * 4 / 3))
    rows = math.ceil(len(picks) / cols)
    sheet = Image.new("RGB", (cols * thumb_width, rows * thumb_h), "white")
    draw = ImageDraw.Draw(sheet)
    for k, i in enumerate(picks):
        thumb = Image.fromarray(dataset.rgb(int(i))).resize((thumb_width, thumb_h), Image.Resampling.BILINEAR)
        x, y = (k % cols) * thumb_width, (k // cols) * thumb_h
        sheet.paste(thumb, (x, y))
        draw.rectangle((x, y, x + 34, y + 12), fill="black")
        draw.text((x + 2, y + 1), f"{i:04d}", fill="white")
    path = Path(out)
    sheet.save(path)
    return path


def plot_trajectory(poses: np.ndarray, mesh: trimesh.Trimesh, out: str | Path, title: str = "",
                    numbered: bool | None = None, labels: Sequence[str] | None = None) -> Path:
    """Save a 3D plot and a top view of camera positions (with viewing directions) around the target.

    Args:
        poses: (N, 4, 4) camera-to-world matrices (OpenCV convention), in capture order.
        mesh: the target, drawn as a light surface.
        out: PNG path.
        title: figure title.
        numbered: print each view's index; default: only when there are at most 40 views.
        labels: legend-free text per camera instead of its index.
    """
    poses = np.asarray(poses, dtype=np.float64)
    pos, fwd = poses[:, :3, 3], poses[:, :3, 2]
    numbered = len(poses) <= 40 if numbered is None else numbered
    fig = plt.figure(figsize=(12, 5.5))
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    ax3.plot_trisurf(mesh.vertices[:, 0], mesh.vertices[:, 1], mesh.vertices[:, 2], triangles=mesh.faces,
                     color="0.75", alpha=0.6, linewidth=0)
    order = np.linspace(0, 1, len(pos))
    ax3.plot(*pos.T, color="0.4", linewidth=0.8)
    ax3.scatter(*pos.T, c=order, cmap="viridis", s=14, depthshade=False)
    ax3.quiver(*pos.T, *(0.25 * fwd).T, color="tab:red", linewidth=0.5, arrow_length_ratio=0.2)
    radius = np.abs(pos).max()
    ax3.set(xlim=(-radius, radius), ylim=(-radius, radius), zlim=(0, radius), xlabel="x (m)",
            ylabel="y (m)", zlabel="z (m)", box_aspect=(1, 1, 0.5))
    ax3.set_title(f"{len(poses)} views (colour: capture order)")
    top = fig.add_subplot(1, 2, 2)
    footprint = mesh.vertices[:, :2]
    top.fill(*footprint[ConvexHull(footprint).vertices].T, color="0.75", label="target footprint")
    top.plot(pos[:, 0], pos[:, 1], color="0.4", linewidth=0.8)
    sc = top.scatter(pos[:, 0], pos[:, 1], c=order, cmap="viridis", s=18, zorder=3)
    top.quiver(pos[:, 0], pos[:, 1], fwd[:, 0], fwd[:, 1], color="tab:red", scale=25, width=0.003)
    if numbered or labels is not None:
        for i, p in enumerate(pos):
            top.annotate(labels[i] if labels is not None else str(i), p[:2], fontsize=7,
                         xytext=(3, 3), textcoords="offset points")
    top.set(aspect="equal", xlabel="x (m)", ylabel="y (m)", title="top view")
    fig.colorbar(sc, ax=top, label="capture order (0 = first)")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    path = Path(out)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path

