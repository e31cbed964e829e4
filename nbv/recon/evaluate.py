"""Evaluating a reconstruction (what `nbv evaluate` and `nbv plan` write): metrics and a heat map.

Writes DIR/metrics.json, one object per reference given under the keys
`reference` (e.g. the full-scan reconstruction, as in the paper's Table 2) and
`gt` (the ground-truth mesh), each with `chamfer_cm`, `hausdorff_cm`,
`coverage`, `fscore`, `precision`, `recall`, `threshold_cm` and `n_points`;
the inputs and settings are recorded under `run`, the run record (`commit`, `command`, the whole
`config`; `nbv evaluate --config metrics.json` re-runs it) beside them (docs/data-formats.md §8).
Also writes DIR/heatmap.png and DIR/heatmap.ply: distances to the reference,
or to the ground truth when no reference is given (skipped when MESH is a
point cloud; docs/reconstruction.md §6). The files are swapped into DIR together
(`common.io.atomic_folder`; other files in DIR are kept).

`nbv evaluate` refuses (`nbv.recon.overlap.DisjointSurfaces`) a ground truth or reference whose bounding
box misses the reconstruction's or whose size is over 5x apart from it: most often a raw scene file
given where the normalised target was meant (`--normalise-gt` normalises it as `nbv plan` does).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Annotated

import trimesh
from tyro.conf import Positional, arg

from common.io import atomic_folder, check_output_folder, write_json
from common.provenance import run_record
from nbv.recon.config import HeatmapConfig, MetricsConfig
from nbv.recon.heatmap import write_heatmap
from nbv.recon.metrics import Geometry, SurfaceMetrics, evaluate_surfaces, load_geometry
from nbv.recon.overlap import check_overlap
from render.captures.open import refuse_folder
from scenes import list_scenes, load_scene
from scenes.normalise import up_to_z
from scenes.spec import MeshOrientation

OUTPUTS = ("metrics.json", "heatmap.png", "heatmap.ply")
"""Files `nbv evaluate` writes into its output folder."""

GT_FIX = ("A raw scene file where the normalised target was meant? Add --normalise-gt to normalise it as "
          "`nbv plan` does (with its --up-axis), or give the normalised target: `nbv scene export SCENE "
          "--out DIR` writes DIR/mesh.ply (a plan folder holds it as gt.ply).")
"""How to mend a ground truth that does not overlap the reconstruction (`check_overlap`)."""
NORMALISED_FIX = ("The ground truth is normalised: is the reconstruction of this scene, read with the same "
                  "--up-axis?")
"""How to mend a normalised ground truth (`--normalise-gt`) that does not overlap the reconstruction."""
REFERENCE_FIX = ("A reference from another scene or frame? Give a reconstruction of the same normalised "
                 "target (e.g. `nbv reconstruct` of its full scan).")
"""How to mend a reference reconstruction that does not overlap the reconstruction."""


@dataclass(frozen=True, kw_only=True)
class GroundTruth(MeshOrientation):
    """The ground-truth surface: a built-in scene's target, or a mesh / point-cloud file and its up axis."""

    gt: str | None = None
    """Ground truth: a mesh or point-cloud file, read as is but turned z up per --up-axis (e.g. the
    normalised target `nbv scene export` writes), or a built-in scene name / random:SEED (its target
    mesh, no ground)."""
    normalise_gt: bool = False
    """Normalise a --gt mesh file as `nbv plan` and `nbv scan` normalise a scene file (z up per --up-axis,
    centred, base on z = 0, largest side 1 m): give the scene file itself as ground truth."""

    def load(self) -> Geometry:
        """The ground-truth surface, z up."""
        if self.gt is None:
            raise ValueError("no ground truth given (--gt)")
        if Path(self.gt).is_file() and self.normalise_gt:
            return load_scene(self.gt, self.up_axis).target_mesh()
        if Path(self.gt).is_file():
            geometry = load_geometry(self.gt, "gt")
            if self.up_axis == "z":
                return geometry
            vertices = up_to_z(geometry.vertices, self.up_axis)
            if isinstance(geometry, trimesh.Trimesh):
                return trimesh.Trimesh(vertices, geometry.faces, process=False)
            return trimesh.PointCloud(vertices)
        try:
            return load_scene(self.gt).target_mesh()
        except (ValueError, FileNotFoundError) as err:
            raise FileNotFoundError(f"gt {self.gt!r} is neither a mesh file nor a built-in scene "
                                    f"({', '.join(list_scenes())}): {err}") from err


@dataclass(frozen=True, kw_only=True)
class EvaluateConfig:
    """Settings of `nbv evaluate`: the reconstruction, what it is compared with, how, and where to write."""

    mesh: Annotated[Path, Positional, arg(metavar="MESH")]
    """The reconstruction to evaluate: a mesh or point-cloud file (e.g. mesh.ply of `nbv reconstruct`)."""
    reference: Path | None = None
    """A reference reconstruction file (the paper's full 288-view scan)."""
    ground_truth: GroundTruth = GroundTruth()
    """The ground truth."""
    out: Path
    """Folder for metrics.json, heatmap.png and heatmap.ply."""
    metrics: MetricsConfig = MetricsConfig()
    """How surfaces are sampled and compared."""
    heatmap: HeatmapConfig = HeatmapConfig()
    """The heat map's colour scale and views."""
    seed: int = 0
    """Seed of the surface sampling."""
    overwrite: bool = False
    """Replace metrics.json and the heat maps if the folder already holds them."""


def evaluate(config: EvaluateConfig) -> dict[str, SurfaceMetrics]:
    """Compare the mesh with each given reference, write metrics.json and the heat map, return the metrics."""
    gt = config.ground_truth
    if config.reference is None and gt.gt is None:
        raise ValueError("give --reference, --gt or both to compare against")
    out = Path(config.out)
    check_output_folder(out, config.overwrite, OUTPUTS)
    refuse_folder(config.mesh, "MESH")
    refuse_folder(config.reference, "--reference")
    prediction = load_geometry(config.mesh, "mesh")
    references: dict[str, Geometry] = {}
    if gt.gt is not None:
        references["gt"] = gt.load()
        fix = NORMALISED_FIX if gt.normalise_gt else GT_FIX
        check_overlap(prediction, references["gt"], f"--gt {gt.gt}", fix)
    if config.reference is not None:
        references["reference"] = load_geometry(config.reference, "reference")
        check_overlap(prediction, references["reference"], f"--reference {config.reference}", REFERENCE_FIX)
    with atomic_folder(out, config.overwrite, OUTPUTS) as folder:
        return write_evaluation(config, prediction, references, folder)


def write_evaluation(config: EvaluateConfig, prediction: Geometry, references: dict[str, Geometry],
                     folder: Path) -> dict[str, SurfaceMetrics]:
    """Compare `prediction` with each reference; write metrics.json (recording `config`) and the heat map
    into `folder`."""
    gt = config.ground_truth
    metrics = replace(config.metrics, seed=config.seed)
    results = evaluate_surfaces(prediction, references, metrics)
    is_mesh = isinstance(prediction, trimesh.Trimesh)
    heat_against = "reference" if "reference" in references else "gt"
    if is_mesh:
        write_heatmap(prediction, references[heat_against], folder, config.heatmap,
                      title=f"{Path(config.mesh).name}: distance to {heat_against}")
    run = {"mesh": str(config.mesh), "reference": None if config.reference is None else str(config.reference),
           "gt": gt.gt, "up_axis": gt.up_axis, "heatmap_against": heat_against if is_mesh else None,
           "metrics": asdict(metrics), "heatmap": asdict(config.heatmap)}
    write_json(folder / "metrics.json", {**{name: m.as_dict() for name, m in results.items()}, "run": run,
                                         **run_record("nbv evaluate", config)})
    return results


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
