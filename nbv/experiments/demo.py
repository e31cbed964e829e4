"""`make demo`: the main job end to end on a built-in scene.

Stages: the full hemisphere scan (paper Sec. V-B; reused while nothing
changed), Bag of Views refinement (Alg. 1), TSDF fusion of both view sets
(Sec. V-C), evaluation of both against the ground-truth mesh and of the refined
set against the full scan (Sec. VI-B), then a table and pictures: contact
sheet, trajectories, distance heat maps. The online half (paper Sec. IV-VI-A)
follows: the shipped policy plans one pass around a held-out building
(`online_scene`), its views are captured, fused and scored against the ground
truth beside random views, the tuned orbits (the registry's `tuned`
entries) and the depth option (`lookahead`, the registry's `depth_option`)
at the same count (`nbv plan` runs, `online_*/`; one-run planner studies,
`online_study`, under the demo's camera, rendering, fusion and metric
settings).

Everything but the full scan (`OUTPUTS`) is written into one temporary folder and
swapped onto `--out` at the end (`common.io.atomic_folder`), so an interrupted demo
leaves the previous results whole; the cached full scan (`full_scan/`, written
atomically on its own) is carried over as hard links, not re-rendered. A rescan
(--fresh, changed settings) stays even if a later stage is interrupted: the
previous results beside it then record the old scan's settings in results.json.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import trimesh

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import config_record, git_commit, run_record
from nbv.bov.config import BoVConfig
from nbv.bov.refine import Progress, RefineConfig, refine_dataset
from nbv.experiments.paper_numbers import FIG7_GENERALISATION, FULL_SCAN_VIEWS, SEC7_SUMMARY, TABLE2
from nbv.experiments.planner_study import PlannerStudy, run_study
from nbv.experiments.sfm_columns import SFM_HEADER, sfm_cells, sfm_entry
from nbv.experiments.study import FullScanStudy
from nbv.planning.config import PlanSettings
from nbv.planning.registry import depth_planners, image_planners, tuned_planners
from nbv.recon.heatmap import write_heatmap
from nbv.recon.metrics import SurfaceMetrics, evaluate_surfaces
from nbv.recon.tsdf import Reconstruction, reconstruct_dataset, save_reconstruction
from nbv.sfm.config import LinkSettings, SfmOption
from nbv.viz.figures import contact_sheet, plot_trajectory
from render.dataset import ViewDataset, read_dataset
from scenes.catalog import DEFAULT_SCENE
from scenes.model import Scene

ONLINE_PLANNERS = ("random", *tuned_planners(), *depth_planners(), *image_planners())
"""What the online half flies beside the policy at its count: random views, the registry's tuned orbits,
depth options and image-only look-ahead."""
OUTPUTS = ("refined", "recon_full", "recon_refined", "contact_sheet.png", "trajectory_full.png",
           "trajectory_refined.png", "heatmap_refined_vs_full.png", "heatmap_refined_vs_full.ply",
           "heatmap_full_vs_gt.png", "heatmap_full_vs_gt.ply", "results.json", "results.md", "online_policy",
           *(f"online_{name}" for name in ONLINE_PLANNERS),
           "sfm_full", "sfm_refined", "refined_linked", "sfm_refined_linked")
"""What one demo run writes into `--out`, all together (the cached `full_scan/` beside them is kept)."""


@dataclass(frozen=True, kw_only=True)
class DemoConfig(FullScanStudy, SfmOption):
    """Settings of `nbv demo` (--sfm: COLMAP on the full and the refined set, sfm_full/ and sfm_refined/,
    and on the online half's runs; off by default: minutes on the full scan)."""

    out: Path = Path("demo_out")
    """Folder for the datasets, reconstructions, figures and tables."""
    scene: str = DEFAULT_SCENE
    """Built-in scene name, random:SEED, or a mesh path (with --up-axis)."""
    bov: BoVConfig = BoVConfig()
    """The Bag of Views of the refinement."""
    links: LinkSettings = LinkSettings()
    """With --min-matches K (beyond the paper): also the refinement kept registrable, refined_linked/ (the
    paper's set plus the fewest views linking it), its view reduction beside the paper's rule and, with
    --sfm, its registration."""
    fresh: bool = False
    """Rescan even if the output folder already holds a full scan made with these settings."""
    online: bool = True
    """Run the online half: a policy plans a held-out building, beside random views and the tuned orbits."""
    online_scene: str = "alpine_chalet"
    """The held-out building of the online half (never trained on)."""
    policy: str = "policy"
    """The online half's planner: the shipped policy, or policy:CHECKPOINT."""


class Stopwatch:
    """Seconds per named stage, in order."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Time the block as stage `name`."""
        start = time.perf_counter()
        yield
        self.seconds[name] = round(time.perf_counter() - start, 2)


def run_demo(config: DemoConfig, progress: Progress | None = None) -> dict[str, Any]:
    """Run every stage; write `OUTPUTS` (`results.json`, `results.md`, ...) into `out` together.

    `progress` is called with the number of views whose features were just extracted.
    """
    out = Path(config.out)
    scene = config.load(config.scene)
    clock = Stopwatch()
    with clock.stage("scan_s"):
        full = config.full_scan(scene, out / "full_scan", config.fresh)
    with atomic_folder(out, overwrite=True, outputs=OUTPUTS) as folder:
        results, table = demo_stages(config, scene, full, folder, clock, progress)
        write_json(folder / "results.json", results)
        write_text(folder / "results.md", table)
    return results


def demo_stages(config: DemoConfig, scene: Scene, full: ViewDataset, folder: Path, clock: Stopwatch,
                progress: Progress | None) -> tuple[dict[str, Any], str]:
    """Refine, reconstruct, evaluate and draw into `folder`; the results and their Markdown table."""
    out = Path(config.out)
    with clock.stage("refine_s"):
        refine = RefineConfig(dataset=full.root, out=folder / "refined", bov=config.bov, seed=config.seed,
                              overwrite=True)
        refined = refine_dataset(refine, progress)
    linked = None
    if config.links.on:
        with clock.stage("refine_linked_s"):
            linked = refine_dataset(replace(refine, out=folder / "refined_linked", links=config.links))
    with clock.stage("reconstruct_s"):
        recon_full = reconstruct_dataset(full, config.recon)
        recon_refined = reconstruct_dataset(full, config.recon, refined["kept"])
        save_reconstruction(recon_full, folder / "recon_full")
        save_reconstruction(recon_refined, folder / "recon_refined")
    gt = scene.target_mesh()
    with clock.stage("evaluate_s"):
        metrics_config = config.seeded_metrics
        metrics = {
            "full": evaluate_surfaces(recon_full.mesh, {"gt": gt}, metrics_config),
            "refined": evaluate_surfaces(recon_refined.mesh, {"gt": gt, "reference": recon_full.mesh},
                                         metrics_config),
        }
    with clock.stage("figures_s"):
        figures = draw_figures(config, scene.name, full, recon_full, recon_refined, gt, folder)
    sfm = sfm_stage(config, full, folder, clock, linked is not None) if config.sfm else {}
    online = {}
    if config.online:
        with clock.stage("online_s"):
            online = online_half(config, folder)
    results = {
        "config": config_record(config),
        "commit": git_commit(),
        "scene": scene.name,
        "views_full": len(full),
        "views_refined": len(refined["kept"]),
        "kept": refined["kept"],
        **({} if linked is None else {"views_refined_linked": len(linked["kept"]), "links": linked["links"]}),
        "metrics": {name: {ref: m.as_dict() for ref, m in per.items()} for name, per in metrics.items()},
        "timings": clock.seconds,
        "figures": {k: str(out / Path(v).name) for k, v in figures.items()},
        "online": online,
        **({"sfm": sfm} if config.sfm else {}),
    }
    return results, results_table(results, metrics)


def sfm_stage(config: DemoConfig, full: ViewDataset, folder: Path, clock: Stopwatch,
              linked: bool = False) -> dict[str, Any]:
    """COLMAP on the full scan, on the refined set (`folder/refined`) and, with `linked`, on the registrable
    one (`folder/refined_linked`) into `folder/sfm_full`, `sfm_refined`, `sfm_refined_linked`; each set's
    headline (`nbv.sfm.check.sfm_summary`)."""
    from nbv.sfm.check import sfm_summary  # pycolmap only when asked for

    record = run_record("nbv demo", config)
    found = {}
    sets = [("full", full), ("refined", read_dataset(folder / "refined"))]
    if linked:
        sets.append(("refined_linked", read_dataset(folder / "refined_linked")))
    for name, dataset in sets:
        with clock.stage(f"sfm_{name}_s"):
            found[name] = sfm_summary(dataset, config.sfm_settings, config.seed, folder / f"sfm_{name}",
                                      record)
    return found


def online_study(config: DemoConfig, folder: Path, name: str, planner: str,
                 views: int | None) -> PlannerStudy:
    """One run of the online half as a planner study: `planner` on `online_scene` at `views` (None: its
    own count), into `folder/online_<name>`, under the demo's camera, rendering, fusion and metrics,
    scored against the ground truth."""
    settings = PlanSettings(camera=config.camera, render=config.render, recon=config.recon,
                            metrics=config.metrics, full_scan=False)
    return PlannerStudy(scenes=(config.online_scene,), up_axis=config.up_axis, planners=(planner,),
                        seeds=(config.seed,), budgets=(views,), settings=settings, out=folder,
                        runs=f"online_{name}", sfm=config.sfm, sfm_settings=config.sfm_settings)


def online_half(config: DemoConfig, folder: Path) -> dict[str, dict[str, Any]]:
    """The policy's one pass around `online_scene`, then random views, the registry's tuned orbits
    (`tuned_planners`), depth options (`depth_planners`) and image-only look-ahead (`image_planners`) at its
    count: `nbv plan` runs."""
    policy = run_study(online_study(config, folder, "policy", config.policy, None))[0].plan()
    keep = ("views", "planning_s", "gt", "flight_m", "azimuth_reversals", *(("sfm",) if config.sfm else ()))
    runs = {"policy": policy}
    for name in ONLINE_PLANNERS:
        runs[name] = run_study(online_study(config, folder, name, name, policy["views"]))[0].plan()
    return {name: {k: plan[k] for k in keep} for name, plan in runs.items()}


def draw_figures(config: DemoConfig, name: str, full: ViewDataset, recon_full: Reconstruction,
                 recon_refined: Reconstruction, gt: trimesh.Trimesh, out: Path) -> dict[str, Path]:
    """The demo's pictures, written into `out`: contact sheet, both trajectories, both heat maps."""
    size = f"N={config.bov.ranges}, W={config.bov.words}"
    return {
        "contact_sheet": contact_sheet(full, out / "contact_sheet.png"),
        "trajectory_full": plot_trajectory(full.poses(), gt, out / "trajectory_full.png",
                                           f"{name}: full hemisphere scan"),
        "trajectory_refined": plot_trajectory(read_dataset(out / "refined").poses(), gt,
                                              out / "trajectory_refined.png",
                                              f"{name}: Bag of Views refinement ({size})"),
        "heatmap_refined_vs_full": write_heatmap(recon_refined.mesh, recon_full.mesh, out,
                                                 name="heatmap_refined_vs_full",
                                                 title="refined vs full-scan reconstruction")[1],
        "heatmap_full_vs_gt": write_heatmap(recon_full.mesh, gt, out, name="heatmap_full_vs_gt",
                                            title="full-scan reconstruction vs ground truth")[1],
    }


def results_table(results: dict[str, Any], metrics: dict[str, dict[str, SurfaceMetrics]]) -> str:
    """The demo's Markdown table, with the paper's Table 2 range and Sec. VII summary beside our numbers."""
    views = {"full": results["views_full"], "refined": results["views_refined"]}
    rows = [[name, views[name], ref, f"{m.chamfer_cm:.3f}", f"{m.hausdorff_cm:.3f}", f"{m.coverage:.3f}",
             f"{m.fscore:.3f}"] for name, per in metrics.items() for ref, m in per.items()]
    table = markdown_table(["view set", "views", "vs", "Chamfer (cm)", "Hausdorff (cm)", "coverage",
                            "F-score"], rows)
    paper_views = [v for t in TABLE2.values() for v in t["views"]]
    paper_chamfer = [v for t in TABLE2.values() for v in t["chamfer_cm"]]
    paper_hausdorff = [v for t in TABLE2.values() for v in t["hausdorff_cm"]]
    reduction = 100 * (1 - results["views_refined"] / results["views_full"])
    lines = [
        f"# Demo: {results['scene']} (commit {results['commit']})",
        "",
        table,
        f"Ours: Bag of Views kept {results['views_refined']} of {results['views_full']} views "
        f"({reduction:.1f} % fewer).",
        f"Paper (Table 2, two buildings, 12 settings each, of {FULL_SCAN_VIEWS} views): kept "
        f"{min(paper_views)} to {max(paper_views)} views; vs the full scan Chamfer "
        f"{min(paper_chamfer):.2f} to {max(paper_chamfer):.2f} cm, Hausdorff {min(paper_hausdorff):.2f} to "
        f"{max(paper_hausdorff):.2f} cm; its summary: {SEC7_SUMMARY['fewer_views_pct']} % fewer views and "
        f"{SEC7_SUMMARY['lower_error_pct']} % lower error (Sec. VII).",
        *linked_lines(results),
        "",
        "Timings (s): " + ", ".join(f"{k} {v}" for k, v in results["timings"].items()),
        "",
    ]
    if results["online"]:
        scene = results["config"]["online_scene"]
        rows = [[name, run["views"], f"{run['planning_s']:.2f}", f"{run['gt']['chamfer_cm']:.3f}",
                 f"{run['gt']['hausdorff_cm']:.3f}", f"{run['gt']['coverage']:.3f}", f"{run['flight_m']:.1f}",
                 run["azimuth_reversals"]] for name, run in results["online"].items()]
        header = ["planner", "views", "planning (s)", "Chamfer vs gt (cm)", "Hausdorff vs gt (cm)",
                  "coverage vs gt", "flight (m)", "azimuth reversals"]
        lines += [f"## Online half: {scene} (held out): the policy's one pass, random views, the tuned "
                  "orbits and the depth option (it reads the depth it measures) at its count", "",
                  markdown_table(header, rows),
                  "Trajectory: online_policy/trajectory.png. Paper Fig. 7 (vs its full scan): "
                  + ", ".join(f"{k} Hausdorff {v['hausdorff_cm']} cm, Chamfer {v['chamfer_cm']} cm"
                              for k, v in FIG7_GENERALISATION.items()) + ".", ""]
    return "\n".join(lines + sfm_lines(results))


def linked_lines(results: dict[str, Any]) -> list[str]:
    """With --min-matches, the registrable refinement's view reduction beside the paper's rule; else none."""
    if "links" not in results:
        return []
    links, full = results["links"], results["views_full"]
    paper, linked = len(links["paper_kept"]), results["views_refined_linked"]
    return [f"Registrable refinement (--min-matches {links['min_matches']}, beyond the paper): kept {linked} "
            f"of {full} views ({100 * (1 - linked / full):.1f} % fewer), the paper's rule's {paper} "
            f"({100 * (1 - paper / full):.1f} % fewer) plus {len(links['added'])} linking views; "
            f"{len(links['unlinked'])} kept view(s) unlinked (refined_linked/)."]


def sfm_lines(results: dict[str, Any]) -> list[str]:
    """With --sfm, the demo's structure-from-motion table: the full and the refined set, then the online
    half's runs; else none."""
    if "sfm" not in results:
        return []
    sets = {f"{name.replace('_', ' ')} set": doc for name, doc in results["sfm"].items()}
    sets.update({f"online {name}": run["sfm"] for name, run in results["online"].items()})
    rows = [[name, *sfm_cells([sfm_entry(doc)])] for name, doc in sets.items()]
    return ["## Structure from motion (COLMAP): views registered in the largest model, models, its mean "
            "camera-centre error after a similarity fit (sfm_full/, sfm_refined/, sfm_refined_linked/ with "
            "--min-matches, online_*/sfm/)", "",
            markdown_table(["view set", *SFM_HEADER], rows), ""]
