"""Pictures of `make tables` beyond Table 2: coverage against view budget and against metres flown, and
the one-pass episodes."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from nbv.viz.figures import save_figure


def oracle_note(rows: Sequence[dict[str, Any]]) -> str:
    """The title's note on the dashed oracle curve, empty where no row is the oracle's.

    Example:
        >>> oracle_note([{"planner": "orbit"}]), oracle_note([{"planner": "oracle"}])
        ('', ' (oracle dashed: an upper bound)')
    """
    return " (oracle dashed: an upper bound)" if any(r["planner"] == "oracle" for r in rows) else ""


def plot_budget_curves(rows: dict[str, Sequence[dict[str, Any]]], budgets: Sequence[int],
                       out: str | Path) -> Path:
    """Each measure (a row of panels: reconstructed, then visible coverage %) against views for every
    planner (error bars: one std over seeds), a panel per building and one for the mean over buildings;
    each legend entry gives the curve's AUC."""
    measures = list(rows)
    scenes = list(dict.fromkeys(r["scene"] for r in rows[measures[0]]))
    fig = Figure(figsize=(4.6 * len(scenes), 4.2 * len(measures)))
    axes = fig.subplots(len(measures), len(scenes), squeeze=False)
    for line, measure in zip(axes, measures):
        for ax, scene in zip(line, scenes):
            for i, row in enumerate(r for r in rows[measure] if r["scene"] == scene):
                dashed = "--" if row["planner"] == "oracle" else "-"
                ax.errorbar(budgets, row["mean"], yerr=row["std"], marker="o", capsize=3, linestyle=dashed,
                            color=f"C{i % 10}", label=f"{row['planner']} (AUC {row['auc']:.1f})")
            ax.set(xlabel="views", ylabel=f"{measure} % of the true surface", title=scene,
                   xticks=list(budgets))
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    fig.suptitle("Coverage against view budget" + oracle_note(rows[measures[0]]))
    return save_figure(fig, out)


def plot_coverage_metres(coverage: Sequence[dict[str, Any]], metres: Sequence[dict[str, Any]],
                         out: str | Path) -> Path:
    """Coverage % against metres flown for every planner, one point per view budget (error bars: one std
    over seeds both ways), a panel per building and one for the mean over buildings; rows as
    `plot_budget_curves` takes them, `metres` in the same order as `coverage`."""
    scenes = list(dict.fromkeys(r["scene"] for r in coverage))
    fig = Figure(figsize=(4.6 * len(scenes), 4.2))
    axes = fig.subplots(1, len(scenes), squeeze=False)[0]
    for ax, scene in zip(axes, scenes):
        flown = {r["planner"]: r for r in metres if r["scene"] == scene}
        for i, row in enumerate(r for r in coverage if r["scene"] == scene):
            dashed = "--" if row["planner"] == "oracle" else "-"
            metre = flown[row["planner"]]
            ax.errorbar(metre["mean"], row["mean"], xerr=metre["std"], yerr=row["std"], marker="o", capsize=3,
                        linestyle=dashed, color=f"C{i % 10}", label=row["planner"])
        ax.set(xlabel="metres flown along the viewing shell", ylabel="coverage % of the true surface",
               title=scene)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Coverage against metres flown, one point per view budget" + oracle_note(coverage))
    return save_figure(fig, out)


def plot_episodes(rows: Sequence[dict[str, Any]], out: str | Path) -> Path:
    """Bars of our one-pass episodes per building (mean ± std over seeds), one colour per policy, for
    Hausdorff, Chamfer and coverage against the full scan, the paper's value as a red marker where it gives
    one."""
    panels = (("ref_hausdorff_cm", "hausdorff_cm", 1.0, "Hausdorff cm (vs full scan)"),
              ("ref_chamfer_cm", "chamfer_cm", 1.0, "Chamfer cm (vs full scan)"),
              ("ref_coverage", "coverage", 100.0, "coverage % (vs full scan)"))
    scenes = list(dict.fromkeys((r["scene"], r["role"]) for r in rows))
    policies = list(dict.fromkeys(r["policy"] for r in rows))
    width = 0.8 / len(policies)
    fig = Figure(figsize=(4.4 * len(panels), 4.2))
    axes = fig.subplots(1, len(panels))
    for ax, (key, paper_key, scale, title) in zip(axes, panels):
        for k, policy in enumerate(policies):
            mine = [(scenes.index((r["scene"], r["role"])), r) for r in rows if r["policy"] == policy]
            ax.bar([i + (k - (len(policies) - 1) / 2) * width for i, _ in mine], [r[key] for _, r in mine],
                   width, yerr=[r[f"{key}_std"] for _, r in mine], capsize=3, color=f"C{k}",
                   label=f"ours: {policy}")
        paper = {(r["scene"], r["role"]): r["paper"] for r in rows}  # the same for every policy
        marked = [(i, scale * paper[s][paper_key]) for i, s in enumerate(scenes) if paper_key in paper[s]]
        if marked:
            ax.plot(*zip(*marked), "D", color="tab:red", label="paper")
        ax.set_xticks(range(len(scenes)), [f"{scene}\n{role}" for scene, role in scenes], fontsize=7)
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=8)
    fig.suptitle("Fig. 1 and Fig. 7: one pass around the target")
    return save_figure(fig, out)
