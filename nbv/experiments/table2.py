"""`make tables`: the paper's Table 2 (and Fig. 6) measured by our code, beside the paper's numbers.

For each building: the full 288-view hemisphere scan (paper Sec. V-B) and its
TSDF reconstruction (the reference, as in the paper); SIFT features extracted
once; Alg. 1 over the grid of N ranges x W words; each refined set
reconstructed and compared with the reference (the paper's Hausdorff and
Chamfer) and with the ground-truth mesh (which the paper did not have).
Every number written here comes from this run; the paper's stand in their own
labelled columns.

Each building is a unit of work (`measure_scene_unit`: its rows and heat maps,
written atomically into a scratch folder beside `--out`), so `--workers N` or
`--ray auto|ADDRESS` measure the buildings side by side (`nbv.fanout`; on a
cluster the scratch folder must be shared). At the end
the tables, the chart and `fig6/` (`OUTPUTS`) are swapped onto `--out` together
(`common.io.atomic_folder`): an interrupted run keeps the previous results whole,
and what else `--out` holds (e.g. `paper_results/planners/`) is carried over,
only in the last seconds, so a run writing there meanwhile is not lost.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from tyro.conf import Suppress

from common.io import atomic_folder, markdown_table, scratch_folder, write_json, write_text
from common.provenance import config_record, git_commit, portable_record
from nbv.bov.config import BoVRule
from nbv.bov.refine import DatasetRun, Progress, kept_view_grid, load_views
from nbv.bov.sweep import PAPER_RANGES, PAPER_WORDS, write_csv
from nbv.experiments.paper_numbers import FULL_SCAN_VIEWS, TABLE2, TABLE2_RANGES, TABLE2_WORDS
from nbv.experiments.study import FullScanStudy
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_tasks
from nbv.fanout.task import Task
from nbv.recon.heatmap import write_heatmap
from nbv.recon.metrics import evaluate_surfaces
from nbv.recon.tsdf import reconstruct_dataset
from nbv.viz.figures import plot_table2

COLUMNS = {"ranges": "N", "words": "W", "views": "views", "paper_views": "paper views",
           "ref_hausdorff_cm": "Hausdorff ref", "paper_hausdorff_cm": "paper Hausdorff",
           "ref_chamfer_cm": "Chamfer ref", "paper_chamfer_cm": "paper Chamfer", "gt_coverage": "coverage gt",
           "gt_chamfer_cm": "Chamfer gt"}
"""Row key -> column title of table2.md, after the building."""
OUTPUTS = ("table2.json", "table2.csv", "table2.md", "table2.png", "fig6")
"""What `nbv tables` writes into `--out`, all together (other entries there are kept)."""


@dataclass(frozen=True, kw_only=True)
class TablesConfig(FullScanStudy):
    """Settings of `nbv tables`."""

    out: Path = Path("paper_results")
    """Folder for the tables (CSV, Markdown, JSON) and figures (PNG)."""
    scenes: tuple[str, ...] = ("medieval_tavern", "forest_ruin_house")
    """Buildings of Table 2 (the paper's two; any scene names work)."""
    ranges: tuple[int, ...] = PAPER_RANGES
    """N values of the grid (size of the Bag of Views)."""
    words: tuple[int, ...] = PAPER_WORDS
    """W values of the grid (words per view range)."""
    rule: BoVRule = BoVRule()
    """The Bag of Views rule and features of every cell."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the buildings are measured: this process, local workers or Ray (not recorded: it changes no
    number)."""
    seeds: tuple[int, ...] = (0, 1, 2)
    """Seeds of the renders, the Bag of Views and the metric samples: each gives its own full scans and
    grid; tables give the mean and std over them (Fig. 6 shows the first)."""
    seed: Suppress[int] = 0
    """The seed being measured (set from `seeds`)."""

    def __post_init__(self) -> None:
        if not self.seeds or min(self.seeds) < 0:
            raise ValueError(f"tables need at least one seed, each >= 0, got {self.seeds}")


def paper_cell(scene: str, n: int, w: int) -> dict[str, Any]:
    """The paper's Table 2 numbers for one building and (N, W), or {} where it has none."""
    columns = list(zip(TABLE2_RANGES, TABLE2_WORDS))
    if scene not in TABLE2 or (n, w) not in columns:
        return {}
    column = columns.index((n, w))
    return {key: values[column] for key, values in TABLE2[scene].items()}


def _corners(config: TablesConfig) -> set[tuple[int, int]]:
    """The grid's four corner cells, whose heat maps are Fig. 6."""
    return {(n, w) for n in (min(config.ranges), max(config.ranges))
            for w in (min(config.words), max(config.words))}


def measure_scene(name: str, config: TablesConfig, progress: Progress | None = None,
                  fig6: Path | None = None) -> list[dict[str, Any]]:
    """Table 2 rows of one building: the full scan against ground truth, then one row per (N, W).

    Writes the Fig. 6 heat maps of the grid's corner cells into `fig6` (None: none).
    `progress` is called once per row measured.
    """
    scene = config.load(name)
    full = config.full_scan(scene)
    _, feats, azimuths = load_views(DatasetRun(dataset=full.root, seed=config.seed), config.rule)
    grid = kept_view_grid([f.descriptors for f in feats], azimuths, config.ranges, config.words, config.rule,
                          config.seed)
    metrics = config.seeded_metrics
    reference = reconstruct_dataset(full, config.recon).mesh
    gt = scene.target_mesh()
    full_vs_gt = evaluate_surfaces(reference, {"gt": gt}, metrics)["gt"]
    rows = [{"scene": name, "seed": config.seed, "ranges": "-", "words": "-", "views": len(full),
             "paper_views": FULL_SCAN_VIEWS,
             **_prefixed("gt", full_vs_gt.as_dict())}]
    _tick(progress)
    for (n, w), result in grid.items():
        recon = reconstruct_dataset(full, config.recon, result.kept).mesh
        m = evaluate_surfaces(recon, {"reference": reference, "gt": gt}, metrics)
        paper = paper_cell(name, n, w)
        rows.append({"scene": name, "seed": config.seed, "ranges": n, "words": w, "views": len(result.kept),
                     "paper_views": paper.get("views"), **_prefixed("ref", m["reference"].as_dict()),
                     "paper_hausdorff_cm": paper.get("hausdorff_cm"),
                     "paper_chamfer_cm": paper.get("chamfer_cm"), **_prefixed("gt", m["gt"].as_dict())})
        if fig6 is not None and (n, w) in _corners(config):
            title = f"{name}: N={n}, W={w}, {len(result.kept)} views vs the {len(full)}-view scan"
            write_heatmap(recon, reference, fig6, name=f"fig6_{name}_N{n}_W{w}", title=title)
        _tick(progress)
    return rows


def measure_scene_unit(name: str, config: TablesConfig, folder: Path, progress: Progress | None = None,
                       heatmaps: bool = True) -> None:
    """`measure_scene` as a unit of work: `folder/rows.json` and (with `heatmaps`) the heat maps in
    `folder/fig6/`, written together (`common.io.atomic_folder`)."""
    with atomic_folder(folder, overwrite=True) as tmp:
        (tmp / "fig6").mkdir()
        rows = measure_scene(name, config, progress, tmp / "fig6" if heatmaps else None)
        write_text(tmp / "rows.json", json.dumps(rows))


def _tick(progress: Progress | None) -> None:
    if progress is not None:
        progress(1)


def _prefixed(prefix: str, metrics: dict[str, float]) -> dict[str, float]:
    keys = ("chamfer_cm", "hausdorff_cm", "coverage", "fscore")
    return {f"{prefix}_{k}": round(metrics[k], 4) for k in keys}


def run_tables(config: TablesConfig, progress: Progress | None = None) -> list[dict[str, Any]]:
    """Measure every scene at every seed and write `table2.csv`, `table2.md`, `table2.json` (the rows:
    mean and std over seeds; and every seed's rows), `table2.png` and `fig6/` (the first seed's).

    `progress` is called once per row measured: 1 + len(ranges) * len(words) per scene and seed.
    """
    out = Path(config.out)
    start = time.perf_counter()
    with scratch_folder(out) as work:
        # In this process the rows tick one by one; elsewhere a building's rows tick when it is done.
        here = config.executor.ray is None and config.executor.workers == 1
        units = [Task(f"Table 2 rows of {name} (scene {i}, seed {seed})", measure_scene_unit,
                      {"name": name, "config": replace(config, seed=seed),
                       "folder": work / f"seed{seed}-scene{i}", "progress": progress if here else None,
                       "heatmaps": seed == config.seeds[0]},
                      work / f"seed{seed}-scene{i}" / "rows.json")
                 for seed in config.seeds for i, name in enumerate(config.scenes)]
        per_scene = 1 + len(config.ranges) * len(config.words)
        run_tasks(units, config.executor, None if here or progress is None else lambda _: progress(per_scene))
        seed_rows, fig6 = [], work / "fig6"
        fig6.mkdir()
        for unit in units:
            seed_rows += json.loads(unit.result.read_text())
            for image in sorted((unit.result.parent / "fig6").iterdir()):
                image.rename(fig6 / image.name)
        rows = mean_rows(seed_rows)
        record = portable_record(config_record(config, omit=("executor",)))
        header = {"command": f"make tables  (nbv tables --out {out})", "commit": git_commit(),
                  "seconds": round(time.perf_counter() - start, 1), "config": record}
        with atomic_folder(out, overwrite=True, outputs=OUTPUTS) as folder:
            fig6.rename(folder / "fig6")
            write_csv(folder / "table2.csv", rows, fieldnames=list(rows[-1]))
            write_text(folder / "table2.md", table2_markdown(rows, header))
            plot_table2(rows, folder / "table2.png")
            write_json(folder / "table2.json", {**header, "rows": rows, "seed_rows": seed_rows})
    return rows


MEASURED = ("views", "ref_hausdorff_cm", "ref_chamfer_cm", "gt_chamfer_cm", "gt_hausdorff_cm", "gt_coverage",
            "gt_fscore")
"""Row keys measured per seed: averaged over seeds, with their std beside them (`<key>_std`)."""


def mean_rows(seed_rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per building and cell, in first-seen order: each measured key's mean over seeds and its
    population std (`<key>_std`); other keys from the first seed's row, `seeds` the seeds.

    Example:
        >>> rows = mean_rows([{"scene": "a", "seed": 0, "ranges": 5, "words": 10, "views": 10},
        ...                   {"scene": "a", "seed": 1, "ranges": 5, "words": 10, "views": 14}])
        >>> rows[0]["views"], rows[0]["views_std"], rows[0]["seeds"]
        (12.0, 2.0, [0, 1])
    """
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for row in seed_rows:
        groups.setdefault((row["scene"], row["ranges"], row["words"]), []).append(row)
    rows = []
    for group in groups.values():
        row = {k: v for k, v in group[0].items() if k != "seed"}
        row["seeds"] = [r.get("seed") for r in group]
        for key in MEASURED:
            values = [r[key] for r in group if r.get(key) is not None]
            if values:
                row[key] = round(float(np.mean(values)), 4)
                row[f"{key}_std"] = round(float(np.std(values)), 4)
        rows.append(row)
    return rows


def table2_markdown(rows: list[dict[str, Any]], header: dict[str, Any]) -> str:
    """Table 2 as Markdown: ours beside the paper's, per building and (N, W)."""
    def show(row: dict[str, Any], key: str) -> str:
        value = row.get(key)
        if value is None:
            return "-"
        text = f"{value:.4g}" if isinstance(value, float) else str(value)
        spread = row.get(f"{key}_std")
        return f"{text} ± {spread:.2g}" if spread is not None and len(row.get("seeds", [])) > 1 else text

    seeds = ", ".join(map(str, header["config"]["seeds"]))
    intro = (f"Measured by `{header['command']}` at commit {header['commit']} in {header['seconds']} s; "
             f"mean ± std over seeds {seeds} (renders, Bag of Views and metric samples); settings in "
             "`table2.json`. 'paper' columns are the paper's own numbers (Hatami Gazani et al. "
             "2023, Table 2); distances are in cm against the TSDF reconstruction of the full 288-view scan "
             "('ref', as in the paper) and against the ground-truth mesh ('gt', which the paper did not "
             "have).")
    table = markdown_table(["building", *COLUMNS.values()],
                           [[r["scene"], *(show(r, k) for k in COLUMNS)] for r in rows])
    return f"# Table 2: Bag of Views size vs kept views and reconstruction error\n\n{intro}\n\n{table}"
