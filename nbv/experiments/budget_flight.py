"""The budget study's flight: metres and azimuth reversals at each view budget, and coverage within metres.

Every run's `plan.json` records its flight from the start view along the viewing shell (`nbv.flight`);
a prefix of a sequential plan flies the plan's first legs (`prefix_flight`), so each budget's metres are
read from the plans the curves are scored on, no new run. A budget in metres: the coverage a planner
reaches within M metres is the most coverage among its plans at the study's view budgets (the prefixes
of a sequential planner's plan, every replanned plan) that fly at most M metres, 0 where none does (a
coarse step function: the view budgets are its only points).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from common.io import markdown_table
from nbv.experiments.planner_study import StudyRun
from nbv.flight import prefix_flight

METRES = (10.0, 20.0, 40.0)
"""Flight budgets of the study, metres along the viewing shell (a 13-view orbit flies about 9-12 m,
13 random views about 32 m)."""
FLIGHT = (("flight_m", "Flight (m) along the viewing shell, start view to last view", "{:.1f}"),
          ("azimuth_reversals", "Azimuth reversals (sign changes of the azimuth step, from the start view)",
           "{:.1f}"))
"""The flight measures: (key of `prefix_flight`, what it is, cell format)."""
Curves = dict[tuple[str, str], list[list[float]]]
"""Per building and planner label, one curve over the budgets per seed."""


def study_flight(runs: list[StudyRun], key: str) -> Curves:
    """One flight measure (`flight_m` or `azimuth_reversals`) per building and planner label: a curve over
    the budgets per seed, read from each run's plan at its budget."""
    curves: dict[tuple[str, str], dict[int, list[float]]] = {}
    for run in runs:
        seeds = curves.setdefault((run.scene, run.label), {})
        seeds.setdefault(run.seed, []).append(float(prefix_flight(run.plan(), run.views)[key]))
    return {name: list(seeds.values()) for name, seeds in curves.items()}


def within_metres(coverage: Curves, metres: Curves, budgets_m: tuple[float, ...]) -> Curves:
    """Per building, planner and seed, the coverage reached within each metre budget: the best coverage
    among the plans flying at most that far (0 where none does).

    Example:
        >>> within_metres({("a", "p"): [[50.0, 70.0]]}, {("a", "p"): [[8.0, 15.0]]}, (5.0, 10.0, 20.0))
        {('a', 'p'): [[0.0, 50.0, 70.0]]}
    """
    found = {}
    for name, seeds in coverage.items():
        found[name] = [[max([c for c, m in zip(cover, flown) if m <= limit], default=0.0)
                        for limit in budgets_m] for cover, flown in zip(seeds, metres[name])]
    return found


def seed_rows(curves: Curves) -> list[dict[str, Any]]:
    """Per building and planner, then per planner over buildings ('mean'): mean and std over seeds (over
    the buildings' seed means for 'mean') at each budget."""
    rows = []
    for (scene, planner), seeds in curves.items():
        values = np.asarray(seeds, dtype=float)
        rows.append({"scene": scene, "planner": planner, "mean": values.mean(0).tolist(),
                     "std": values.std(0).tolist()})
    for planner in dict.fromkeys(p for _, p in curves):
        means = np.asarray([r["mean"] for r in rows if r["planner"] == planner])
        rows.append({"scene": "mean", "planner": planner, "mean": means.mean(0).tolist(),
                     "std": means.std(0).tolist()})
    return rows


def flight_tables(runs: list[StudyRun], coverage: Curves,
                  budgets_m: tuple[float, ...]) -> dict[str, list[dict]]:
    """The study's flight rows (`seed_rows`): metres and reversals at each view budget, and the coverage
    (%, from `coverage`) within each metre budget (`within_metres`)."""
    flight = {key: study_flight(runs, key) for key, _, _ in FLIGHT}
    return {**{key: seed_rows(curves) for key, curves in flight.items()},
            "within_m": seed_rows(within_metres(coverage, flight["flight_m"], budgets_m))}


def flight_markdown(tables: dict[str, list[dict]], budgets: tuple[int, ...],
                    budgets_m: tuple[float, ...]) -> str:
    """The flight sections of budget.md: metres and reversals per view budget, coverage per metre budget."""
    lines = []
    for key, title, fmt in FLIGHT:
        body = [[r["scene"], r["planner"], *(f"{fmt.format(m)} ± {fmt.format(s)}" for m, s in
                                             zip(r["mean"], r["std"]))] for r in tables[key]]
        lines += ["", f"## {title}", "",
                  markdown_table(["building", "planner", *(f"{b} views" for b in budgets)], body)]
    body = [[r["scene"], r["planner"], *(f"{m:.1f} ± {s:.1f}" for m, s in zip(r["mean"], r["std"]))]
            for r in tables["within_m"]]
    lines += ["", "## Coverage (%) of the true surface within a flight budget", "",
              "The most coverage among a planner's plans at the view budgets above (a sequential planner's "
              "prefixes, every replanned plan) that fly at most M metres from the start view; 0 where none "
              "does.", "", markdown_table(["building", "planner", *(f"<= {m:g} m" for m in budgets_m)], body)]
    return "\n".join(lines)
