"""Evaluating a reconstruction (what `nbv evaluate` and `nbv plan` write): metrics and a heat map.

Writes DIR/metrics.json, one object per reference given under the keys
`reference` (e.g. the full-scan reconstruction, as in the paper's Table 2) and
`gt` (the ground-truth mesh), each with `chamfer_cm`, `hausdorff_cm`,
`coverage`, `fscore`, `precision`, `recall`, `threshold_cm` and `n_points`;
the inputs and settings are recorded under `run`. Also writes DIR/heatmap.png
and DIR/heatmap.ply: distances to the reference, or to the ground truth when
no reference is given (skipped when MESH is a point cloud).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path

import trimesh

from nbv.cli.config_args import positional
from nbv.heatmap import HeatmapConfig, write_heatmap
from nbv.metrics import Geometry, MetricsConfig, SurfaceMetrics, evaluate_surfaces, load_geometry
from render.dataset import write_json
from scenes import list_scenes, load_scene


@dataclass(frozen=True)
class EvaluateCommand:
    """What `nbv evaluate` compares and where it writes."""

    mesh: Path = positional()
    """The reconstruction to evaluate: a mesh or point-cloud file (e.g. mesh.ply of `nbv reconstruct`)."""
    reference: Path | None = None
    """A reference reconstruction file (the paper's full 288-view scan)."""
    gt: str | None = None
    """Ground truth: a mesh file (as is), or a built-in scene name (its target mesh, no ground)."""
    out: Path = field(default=None)
    """Folder for metrics.json, heatmap.png and heatmap.ply."""
    overwrite: bool = False
    """Replace metrics.json and the heat maps if the folder already holds them."""


OUTPUTS = ("metrics.json", "heatmap.png", "heatmap.ply")
"""Files `nbv evaluate` writes into its output folder."""


def load_ground_truth(spec: str) -> Geometry:
    """The ground-truth surface named by a file path or a built-in scene name."""
    if Path(spec).is_file():
        return load_geometry(spec, "gt")
    try:
        return load_scene(spec).target_mesh()
    except (ValueError, FileNotFoundError) as err:
        raise FileNotFoundError(f"gt {spec!r} is neither a mesh file nor a built-in scene "
                                f"({', '.join(list_scenes())}): {err}") from err


def evaluate(command: EvaluateCommand, metrics: MetricsConfig = MetricsConfig(),
             heatmap: HeatmapConfig = HeatmapConfig()) -> dict[str, SurfaceMetrics]:
    """Compare the mesh with each given reference, write metrics.json and the heat map, return the metrics."""
    if command.reference is None and command.gt is None:
        raise ValueError("give --reference, --gt or both to compare against")
    existing = [name for name in OUTPUTS if (command.out / name).exists()]
    if existing and not command.overwrite:
        raise FileExistsError(f"{command.out} already holds {', '.join(existing)} (use --overwrite)")
    prediction = load_geometry(command.mesh, "mesh")
    references: dict[str, Geometry] = {}
    if command.gt is not None:
        references["gt"] = load_ground_truth(command.gt)
    if command.reference is not None:
        references["reference"] = load_geometry(command.reference, "reference")
    results = evaluate_surfaces(prediction, references, metrics)
    command.out.mkdir(parents=True, exist_ok=True)
    heat_against = "reference" if "reference" in references else "gt"
    if isinstance(prediction, trimesh.Trimesh):
        write_heatmap(prediction, references[heat_against], command.out, heatmap,
                      title=f"{command.mesh.name}: distance to {heat_against}")
    run = {"mesh": str(command.mesh), "reference": _str(command.reference), "gt": command.gt,
           "heatmap_against": heat_against if isinstance(prediction, trimesh.Trimesh) else None,
           "metrics": asdict(metrics), "heatmap": asdict(heatmap)}
    write_json(command.out / "metrics.json",
               {**{name: m.as_dict() for name, m in results.items()}, "run": run})
    return results


def _str(path: Path | None) -> str | None:
    return None if path is None else str(path)


def format_metrics(results: dict[str, SurfaceMetrics]) -> str:
    """A plain-text table of the metrics, one row per reference."""
    rows = [f"{'against':<10} {'chamfer cm':>10} {'hausdorff cm':>12} {'coverage':>9} {'fscore':>7} "
            f"{'precision':>9} {'recall':>7}"]
    for name, m in results.items():
        rows.append(f"{name:<10} {m.chamfer_cm:>10.3f} {m.hausdorff_cm:>12.3f} {m.coverage:>9.4f} "
                    f"{m.fscore:>7.4f} {m.precision:>9.4f} {m.recall:>7.4f}")
    first = next(iter(results.values()))
    rows.append(f"(threshold {first.threshold_cm:g} cm, {first.n_points} points per surface)")
    return "\n".join(rows)
