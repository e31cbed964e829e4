"""Pictures people look at: contact sheets, trajectories, planner and Table 2 charts, learning curves.

Figures are `matplotlib.figure.Figure` objects saved straight to PNG, so no
pyplot backend (and no display) is involved.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
import trimesh
from matplotlib.figure import Figure
from PIL import Image, ImageDraw
from scipy.spatial import ConvexHull
from tyro.conf import Positional, arg

from common.io import atomic_path
from render.dataset import ViewDataset


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
    with atomic_path(path) as tmp:
        sheet.save(tmp)
    return path


def plot_trajectory(poses: np.ndarray, mesh: trimesh.Trimesh, out: str | Path, title: str = "",
                    numbered: bool | None = None, labels: Sequence[str] | None = None,
                    flown: np.ndarray | None = None) -> Path:
    """Save `trajectory_figure` (the same arguments) to the PNG `out`."""
    return save_figure(trajectory_figure(poses, mesh, title, numbered, labels, flown), out)


def trajectory_figure(poses: np.ndarray, mesh: trimesh.Trimesh, title: str = "", numbered: bool | None = None,
                      labels: Sequence[str] | None = None, flown: np.ndarray | None = None) -> Figure:
    """A 3D plot and a top view of camera positions (with viewing directions) around the target.

    Args:
        poses: (N, 4, 4) camera-to-world matrices (OpenCV convention), in capture order.
        mesh: the target, drawn as a light surface.
        title: figure title.
        numbered: print each view's index; default: only when there are at most 40 views.
        labels: legend-free text per camera instead of its index.
        flown: (M, 3) world positions of the path flown from the start view (`nbv.flight`), drawn instead
            of straight lines between the views, its start marked; default: the straight lines.
    """
    poses = np.asarray(poses, dtype=np.float64)
    pos, fwd = poses[:, :3, 3], poses[:, :3, 2]
    line = pos if flown is None else np.asarray(flown, dtype=np.float64)
    numbered = len(poses) <= 40 if numbered is None else numbered
    fig = Figure(figsize=(12, 5.5))
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    ax3.plot_trisurf(mesh.vertices[:, 0], mesh.vertices[:, 1], mesh.vertices[:, 2], triangles=mesh.faces,
                     color="0.75", alpha=0.6, linewidth=0)
    order = np.linspace(0, 1, len(pos))
    ax3.plot(*line.T, color="0.4", linewidth=0.8)
    ax3.scatter(*pos.T, c=order, cmap="viridis", s=14, depthshade=False)
    ax3.quiver(*pos.T, *(0.25 * fwd).T, color="tab:red", linewidth=0.5, arrow_length_ratio=0.2)
    radius = max(np.abs(pos).max(), np.abs(line).max())
    ax3.set(xlim=(-radius, radius), ylim=(-radius, radius), zlim=(0, radius), xlabel="x (m)",
            ylabel="y (m)", zlabel="z (m)", box_aspect=(1, 1, 0.5))
    ax3.set_title(f"{len(poses)} views (colour: capture order)")
    top = fig.add_subplot(1, 2, 2)
    footprint = mesh.vertices[:, :2]
    top.fill(*footprint[ConvexHull(footprint).vertices].T, color="0.75", label="target footprint")
    top.plot(line[:, 0], line[:, 1], color="0.4", linewidth=0.8, label="flown path" if flown is not None
             else None)
    if flown is not None:
        top.plot(*line[0, :2], "k*", markersize=10, zorder=4, label="start view")
        top.legend(fontsize=7, loc="upper right")
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
    return fig


def plot_planner_comparison(runs: Sequence[dict], paper: dict, out: str | Path, title: str = "") -> Path:
    """Save bar charts of coverage, Chamfer and Hausdorff per planner (mean and std over seeds).

    Args:
        runs: one dict per run with `planner`, `gt` and `reference` metric dicts (`nbv plan`'s plan.json).
        paper: the paper's Fig. 1 figures (`coverage`, `chamfer_cm`, `hausdorff_cm`), drawn as dashed lines.
        out: PNG path.
        title: figure title.
    """
    planners = list(dict.fromkeys(r["planner"] for r in runs))
    panels = (("coverage % (vs full scan)", "reference", "coverage", 100.0),
              ("Chamfer cm (vs full scan)", "reference", "chamfer_cm", 1.0),
              ("Hausdorff cm (vs full scan)", "reference", "hausdorff_cm", 1.0))
    fig = Figure(figsize=(4.2 * len(panels), 4.2))
    axes = fig.subplots(1, len(panels))
    for ax, (label, against, key, scale) in zip(axes, panels):
        values = [[scale * r[against][key] for r in runs if r["planner"] == p] for p in planners]
        ax.bar(range(len(planners)), [np.mean(v) for v in values], yerr=[np.std(v) for v in values],
               color="tab:blue", capsize=4)
        ax.axhline(scale * paper[key], color="tab:red", linestyle="--", label="paper Fig. 1 (SAC)")
        ax.set_xticks(range(len(planners)), planners, rotation=30, ha="right", fontsize=8)
        ax.set_title(label, fontsize=10)
        ax.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    return save_figure(fig, out)


def plot_seed_scores(scores: dict[str, Sequence[float]], out: str | Path, ylabel: str, title: str = "",
                     references: dict[str, float] | None = None) -> Path:
    """Save a chart of one score per candidate: the mean as a bar, each seed as a dot, references dashed."""
    names = list(scores)
    fig = Figure(figsize=(1.2 * len(names) + 3.0, 4.2))
    ax = fig.subplots()
    ax.bar(range(len(names)), [np.mean(scores[n]) for n in names], color="tab:blue", alpha=0.6)
    for i, name in enumerate(names):
        ax.plot([i] * len(scores[name]), scores[name], "o", color="black", markersize=4)
    for (label, value), colour in zip((references or {}).items(), ("tab:red", "tab:green", "tab:orange")):
        ax.axhline(value, color=colour, linestyle="--", label=label)
    ax.set_xticks(range(len(names)), names, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel(ylabel)
    if references:
        ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return save_figure(fig, out)


def training_curves(csv_path: str | Path, window: int = 500) -> dict[str, np.ndarray]:
    """Trailing-window means of a `nbv train` metrics.csv: reward per step, return, steps per episode.

    Each value at a row's `frames` averages the rows of the last `window` frames (that row included),
    weighting each batch by its frames (reward) or its finished episodes (return); NaN where no
    episode finished in the window.
    """
    table = np.genfromtxt(csv_path, delimiter=",", names=True, dtype=np.float64)
    frames = np.atleast_1d(table["frames"])
    per_batch = np.diff(frames, prepend=0.0)
    episodes = np.atleast_1d(table["episodes"])
    returns = np.nan_to_num(np.atleast_1d(table["episode_return"])) * episodes
    weighted = {"frames": per_batch, "reward": np.atleast_1d(table["reward_mean"]) * per_batch,
                "episodes": episodes, "returns": returns}
    starts = np.searchsorted(frames, frames - window, side="right")
    sums = {}
    for name, values in weighted.items():
        cum = np.concatenate([[0.0], np.cumsum(values)])
        sums[name] = cum[1:] - cum[starts]
    finished = sums["episodes"] > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        return {"frames": frames, "reward": sums["reward"] / sums["frames"],
                "return": np.where(finished, sums["returns"] / sums["episodes"], np.nan),
                "steps": np.where(finished, sums["frames"] / sums["episodes"], np.nan)}


def plot_training_curves(runs: dict[str, str | Path], out: str | Path, window: int = 500) -> Path:
    """Save reward per step, episode return and steps per episode against frames for `nbv train` runs.

    Args:
        runs: label -> the run's metrics.csv.
        out: PNG path.
        window: frames averaged over for each point (`training_curves`).
    """
    panels = (("reward", "reward per step"), ("return", "episode return"), ("steps", "steps per episode"))
    validations = {label: Path(csv_path).with_name("validation.csv") for label, csv_path in runs.items()}
    validations = {label: path for label, path in validations.items() if path.is_file()}
    fig = Figure(figsize=(13 + 4.3 * bool(validations), 3.8))
    axes = fig.subplots(1, len(panels) + bool(validations))
    for label, csv_path in runs.items():
        curves = training_curves(csv_path, window)
        for ax, (key, _) in zip(axes, panels):
            ax.plot(curves["frames"], curves[key], label=label)
    for ax, (_, title) in zip(axes, panels):
        ax.set(xlabel="frames (environment steps)", title=f"{title} (last {window} frames)")
        ax.grid(alpha=0.3)
    for label, path in validations.items():
        table = np.genfromtxt(path, delimiter=",", names=True, dtype=np.float64)
        frames, mean = np.atleast_1d(table["frames"]), np.atleast_1d(table["mean"])
        line, = axes[-1].plot(frames, mean, marker=".", label=label)
        best = int(np.flatnonzero(frames == np.atleast_1d(table["best_frames"])[-1])[0])  # policy.pt's
        axes[-1].plot(frames[best], mean[best], "*", markersize=12, color=line.get_color())
    if validations:
        axes[-1].set(xlabel="frames (environment steps)", ylabel="visible coverage %",
                     title="validation buildings (star: the actor kept)")
        axes[-1].grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    return save_figure(fig, out)


@dataclass(frozen=True, kw_only=True)
class PlotTrainingConfig:
    """Settings of `nbv plot-training`: the runs to overlay and the PNG to write."""

    runs: Annotated[tuple[str, ...], Positional, arg(metavar="[LABEL=]RUN")]
    """Run folders of `nbv train`, each as LABEL=RUN_FOLDER or RUN_FOLDER (labelled by its name)."""
    out: Path
    """PNG to write."""
    window: int = 500
    """Frames averaged over per point."""

    def __post_init__(self) -> None:
        if not self.runs:
            raise ValueError("give at least one run folder")
        if self.window < 1:
            raise ValueError(f"window must be >= 1 frame, got {self.window}")


def plot_training(config: PlotTrainingConfig) -> Path:
    """Overlay the learning curves of the configured runs (`plot_training_curves`); return the PNG path."""
    runs = {}
    for spec in config.runs:
        label, _, folder = spec.rpartition("=")
        csv_path = Path(folder) / "metrics.csv"
        if not csv_path.is_file():
            raise FileNotFoundError(f"{csv_path} not found: is {folder} an `nbv train` run folder?")
        runs[label or Path(folder).name] = csv_path
    return plot_training_curves(runs, config.out, config.window)


def plot_table2(rows: Sequence[dict], path: str | Path) -> Path:
    """Kept views and Chamfer (vs the full scan) per (N, W): ours as bars, the paper's as markers.

    Args:
        rows: `nbv tables` rows (`scene`, `ranges`, `words`, `views`, `paper_views`, `ref_chamfer_cm`,
            `paper_chamfer_cm`); rows whose `ranges` is '-' (the full scan) are skipped.
        path: PNG path.
    """
    cells = [r for r in rows if r["ranges"] != "-"]
    scenes = list(dict.fromkeys(r["scene"] for r in cells))
    fig = Figure(figsize=(6.5 * len(scenes), 7))
    axes = fig.subplots(2, len(scenes), squeeze=False)
    panels = (("views", "paper_views", "views kept of 288"),
              ("ref_chamfer_cm", "paper_chamfer_cm", "Chamfer vs full scan (cm)"))
    for col, scene in enumerate(scenes):
        mine = [r for r in cells if r["scene"] == scene]
        x = range(len(mine))
        for row, (key, paper_key, unit) in enumerate(panels):
            ax = axes[row][col]
            ax.bar(x, [r[key] for r in mine], color="tab:blue", label="ours")
            paper = [r[paper_key] for r in mine]
            if any(v is not None for v in paper):
                ax.plot(x, [math.nan if v is None else v for v in paper], "o", color="tab:orange",
                        label="paper")
            ax.set_xticks(list(x), [f"{r['ranges']}/{r['words']}" for r in mine], rotation=45, fontsize=8)
            ax.set(ylabel=unit, xlabel="N ranges / W words", title=scene)
            ax.legend(fontsize=8)
    return save_figure(fig, path)


def save_figure(fig: Figure, out: str | Path) -> Path:
    """Lay out a figure and write it as PNG, atomically."""
    fig.tight_layout()
    path = Path(out)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110)
    return path
