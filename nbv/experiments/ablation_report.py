"""The report of `nbv ablate`: per axis and level, mean +- std over buildings and seeds, beside the reference.

Writes, together (`common.io.atomic_folder`): `ablations.csv`, `ablations.md`,
`ablations.json` (the rows, every unit's measurement and the settings),
`axis_<name>.png` per axis (each metric against the level, error bars one std),
`quality_vs_time.png` (PSNR and repeatability against render time, every
level), `crops.png` (the same crop of one view at every level) and
`README.md` (the table and the findings, stated only as measured).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from PIL import Image

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import config_record, git_commit, portable_record
from nbv.bov.sweep import write_csv
from nbv.experiments.ablation_axes import AXES, REFERENCE, Level, Unit, unit_path
from nbv.viz.ablation import plot_axis, plot_crops, plot_quality_vs_time

if TYPE_CHECKING:
    from nbv.experiments.ablate import AblateConfig

METRICS = (("render_s_per_view", "render s/view", 1.0, ".3f"),
           ("psnr_db", "PSNR dB", 1.0, ".2f"),
           ("ssim", "SSIM", 1.0, ".3f"),
           ("keypoints", "keypoints/view", 1.0, ".0f"),
           ("repeatability", "repeatability", 1.0, ".3f"),
           ("inlier_ratio", "match inlier ratio", 1.0, ".3f"),
           ("kept_views", "kept views", 1.0, ".1f"),
           ("jaccard", "Jaccard vs ref", 1.0, ".2f"),
           ("gt_chamfer_cm", "Chamfer cm (gt)", 1.0, ".3f"),
           ("gt_hausdorff_cm", "Hausdorff cm (gt)", 1.0, ".2f"),
           ("gt_coverage", "coverage % (gt)", 100.0, ".1f"),
           ("greedy_coverage", "greedy coverage % (gt)", 100.0, ".1f"))
"""Reported metrics: (unit key, title, display scale, format)."""
OUTPUTS = ("ablations.csv", "ablations.md", "ablations.json", "quality_vs_time.png", "crops.png", "README.md")
"""What every run writes into `--out` (plus `axis_<name>.png` per axis)."""


def _jaccard(a: list[int], b: list[int]) -> float:
    union = set(a) | set(b)
    return len(set(a) & set(b)) / len(union) if union else 1.0


def level_docs(docs: list[dict[str, Any]], axis: str, level: Level) -> list[dict[str, Any]]:
    """The units of one level (the reference units for the reference level), each with its Jaccard overlap
    with the reference's kept views on the same building and seed."""
    refs = {(d["scene"], d["seed"]): d for d in docs if d["axis"] == REFERENCE}
    chosen = [d for d in docs if (d["axis"] == REFERENCE if level.is_reference
                                  else d["axis"] == axis and d["level"] == level.label)]
    return [{**d, "jaccard": _jaccard(d["kept"], refs[(d["scene"], d["seed"])]["kept"])} for d in chosen]


def summary_rows(docs: list[dict[str, Any]], axes: tuple[str, ...]) -> list[dict[str, Any]]:
    """One row per axis and level: each metric's mean and std (population) over buildings and seeds."""
    rows = []
    for name in axes:
        for level in AXES[name].levels:
            measured = level_docs(docs, name, level)
            row: dict[str, Any] = {"axis": name, "level": level.label, "reference": level.is_reference,
                                   "units": len(measured)}
            for key, _, scale, _ in METRICS:
                values = [scale * d[key] for d in measured if key in d]
                row[f"{key}_mean"] = float(np.mean(values)) if values else None
                row[f"{key}_std"] = float(np.std(values)) if values else None
            rows.append(row)
    return rows


def _cell(row: dict[str, Any], key: str, fmt: str) -> str:
    mean, std = row[f"{key}_mean"], row[f"{key}_std"]
    return "-" if mean is None else f"{mean:{fmt}} ± {std:{fmt}}"


def _shown(rows: list[dict[str, Any]]) -> list[tuple[str, str, float, str]]:
    return [m for m in METRICS if any(r[f"{m[0]}_mean"] is not None for r in rows)]


def ablation_table(rows: list[dict[str, Any]]) -> str:
    """The Markdown table: one row per axis level (the reference marked), mean ± std per metric."""
    metrics = _shown(rows)
    body = [[r["axis"], r["level"] + (" (ref)" if r["reference"] else ""),
             *(_cell(r, key, fmt) for key, _, _, fmt in metrics)] for r in rows]
    return markdown_table(["axis", "level", *(title for _, title, _, _ in metrics)], body)


def findings(rows: list[dict[str, Any]]) -> list[str]:
    """Per axis, the measured range of the main metrics over its levels (level names in brackets)."""
    lines = []
    for name in dict.fromkeys(r["axis"] for r in rows):
        mine = [r for r in rows if r["axis"] == name]
        parts = []
        for key, title, _, fmt in METRICS:
            known = [r for r in mine if r[f"{key}_mean"] is not None]
            if key in ("ssim", "keypoints", "gt_chamfer_cm") or len(known) < 2:
                continue
            lo = min(known, key=lambda r: r[f"{key}_mean"])
            hi = max(known, key=lambda r: r[f"{key}_mean"])
            parts.append(f"{title} {lo[f'{key}_mean']:{fmt}} ({lo['level']}) to {hi[f'{key}_mean']:{fmt}} "
                         f"({hi['level']})")
        lines.append(f"- **{name}** ({AXES[name].title}): " + "; ".join(parts) + ".")
    return lines


def rerun_command(config: AblateConfig) -> str:
    """The `nbv ablate` command line that re-runs `config`'s axes, buildings and seeds."""
    if config.quick:
        return "nbv ablate --quick --out DIR"
    return ("nbv ablate " + " ".join(f"--axis {a}" for a in config.axes) + " "
            + " ".join(f"--scene {s}" for s in config.scenes) + f" --seeds {' '.join(map(str, config.seeds))}"
            + f" --out {config.out}")


def readme(config: AblateConfig, rows: list[dict[str, Any]], header: dict[str, Any]) -> str:
    """README.md of the ablation folder: how it was measured, the table, the findings."""
    ref = config.render
    return "\n".join([
        "# Rendering-quality ablations", "",
        f"Measured by `{header['command']}` at commit {header['commit']} in {header['seconds']:.0f} s on "
        f"{', '.join(config.scenes)} with seeds {', '.join(map(str, config.seeds))} "
        f"({header['units']} units); every setting is in `ablations.json`. Each level changes one render "
        f"setting of the reference ({ref.spp} spp, {ref.integrator} max depth {ref.max_depth}, the scene's "
        f"sun and sky, no sensor effects) and renders a {header['scan_views']}-view hemisphere scan at "
        f"{config.camera.width}x{config.camera.height}. PSNR, SSIM, repeatability and the match inlier "
        f"ratio compare {config.quality_views} scan views with a {config.reference_spp}-spp render of the "
        f"reference setting at the same poses (ground-truth correspondences from depth and poses, "
        f"{config.tolerance_px:g} px); kept views are those Alg. 1 keeps with N={config.bov.ranges}, "
        f"W={config.bov.words}, and Jaccard their overlap with the reference level's on the same building "
        f"and seed; the reconstruction of the kept views is compared with the ground-truth mesh; lighting "
        f"axes also score greedy Bag of Views planning at {config.greedy_views} views. Mean ± std over "
        "buildings and seeds. Render time is the median seconds per RGB-D view on this machine, CPU, "
        "one process.", "",
        ablation_table(rows), "", "## Findings (as measured)", "", *findings(rows), "",
        "Plots: `axis_<name>.png` (each metric against the level), `quality_vs_time.png`, `crops.png`.", ""])


def _crop_images(docs: list[dict[str, Any]], folder: Path,
                 config: AblateConfig) -> dict[str, list[tuple[str, Any]]]:
    """Per axis, (level, image) of the first building and seed's first quality view, where it was saved."""
    scene, seed = config.scenes[0], config.seeds[0]
    grid = {}
    for name in config.axes:
        images = []
        for level in AXES[name].levels:
            unit = Unit(scene, REFERENCE, Level(REFERENCE), seed) if level.is_reference else \
                Unit(scene, name, level, seed)
            path = unit_path(folder, unit).with_suffix(".png")
            if path.exists():
                with Image.open(path) as image:
                    images.append((level.label, np.asarray(image.convert("RGB"))))
        grid[name] = images
    return grid


def write_report(config: AblateConfig, docs: list[dict[str, Any]], folder: Path, seconds: float) -> None:
    """Write every output of the run onto `config.out` together."""
    rows = summary_rows(docs, config.axes)
    header = portable_record({
        "command": rerun_command(config).replace("DIR", str(config.out)), "commit": git_commit(),
        "seconds": round(seconds, 1), "units": len(docs), "scan_views": docs[0]["scan_views"],
        "config": config_record(config, omit=("executor",))})
    outputs = OUTPUTS + tuple(f"axis_{name}.png" for name in AXES)
    with atomic_folder(config.out, overwrite=True, outputs=outputs) as out:
        write_csv(out / "ablations.csv", rows, fieldnames=list(rows[0]))
        write_text(out / "ablations.md", "# Rendering-quality ablations\n\n" + ablation_table(rows))
        write_json(out / "ablations.json", {**header, "rows": rows, "units": docs})
        for name in config.axes:
            plot_axis(AXES[name].title, [r for r in rows if r["axis"] == name], _shown(rows),
                      out / f"axis_{name}.png")
        plot_quality_vs_time(rows, out / "quality_vs_time.png")
        plot_crops(_crop_images(docs, folder, config), out / "crops.png")
        write_text(out / "README.md", readme(config, rows, header))
