"""Issue 26's acceptance from `nbv online`'s runs: does a policy beat the tuned orbit, look, and fly short?

For each policy, against the tuned single ring (`orbit`, chosen on training buildings), on the measure
`nbv online` reports (coverage of the true surface at the fixed budget, mean over seeds per building):
- mean coverage at least `ORBIT_MARGIN` points above the orbit's, never more than `ORBIT_WORST` under it
  on any building;
- at least `RANDOM_MARGIN` points above random views on every building; where the oracle is itself less
  than `ORACLE_GAP` points above random, within `ORACLE_WITHIN` of the oracle instead. Where the oracle was
  not run its coverage is bounded above by 100 %: where random views cover more than 100 - `ORACLE_GAP`, a
  policy at or above 100 - `ORACLE_WITHIN` is within `ORACLE_WITHIN` of any oracle, so it passes there; on
  every other building without the oracle it is held to `RANDOM_MARGIN`;
- at most `FLIGHT_RATIO` times the orbit's metres (mean over buildings and seeds);
- it looks: from the same start view, its camera positions on any two buildings at least `SPREAD_M` apart
  on average (`nbv.flight.spread`), and with every captured image blank its mean coverage at least
  `BLANK_DROP` points lower.
The two tuned rings (`orbit2`), the strongest fixed pattern, are reported beside them without a bar. A
check whose planners were not run reads "n/a" and fails the whole. A named depth option (`lookahead`) is held
to the same checks in a column of its own, but for the blank images: it reads no image, so that check does
not apply to it (its looking shows in the path spread).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from common.io import markdown_table
from nbv.flight.spread import pair_spreads_m
from render.viewpoint import Viewpoint

ORBIT_MARGIN = 3.0
"""Points of mean coverage above the tuned orbit's."""
ORBIT_WORST = -1.0
"""The most any building may fall under the tuned orbit, points (negative)."""
RANDOM_MARGIN = 5.0
"""Points above random views on every building."""
ORACLE_GAP = 6.0
"""Where the oracle is less than this many points above random, the policy is held to the oracle."""
ORACLE_WITHIN = 1.0
"""How close to the oracle, points, on such a building."""
FLIGHT_RATIO = 1.5
"""The most metres flown, as a multiple of the tuned orbit's."""
SPREAD_M = 0.2
"""The least mean distance between camera positions on two buildings from the same start, metres."""
BLANK_DROP = 3.0
"""Points of mean coverage lost with blank images, at least."""

Runs = Mapping[str, Mapping[str, Sequence[dict]]]
"""Runs per building, then per planner label: each a `nbv compare` run record (gt, flight_m, viewpoints)."""


def per_building(runs: Runs, label: str, value: Callable[[dict], float]) -> dict[str, float]:
    """Per building, the mean over seeds of `value` of the planner's run records."""
    return {scene: float(np.mean([value(r) for r in by[label]])) for scene, by in runs.items()}


def mean_coverage(runs: Runs, label: str) -> dict[str, float]:
    """Per building, the planner's mean coverage of the true surface over seeds, percent."""
    return per_building(runs, label, lambda r: 100.0 * r["gt"]["coverage"])


def mean_flight(runs: Runs, label: str) -> float:
    """The planner's metres per scan, mean over buildings and seeds."""
    return float(np.mean([r["flight_m"] for by in runs.values() for r in by[label]]))


def policy_checks(runs: Runs, blank: Runs | None, policy: str, reads_images: bool = True) -> list[dict]:
    """The acceptance checks of one policy: each {check, bar, value, passed} (value None: not measurable;
    passed None: no bar, as for the blank images of a planner that reads none, `reads_images` False)."""
    have = set.intersection(*(set(by) for by in runs.values()))
    mine = mean_coverage(runs, policy)
    overall = building_mean(mine)
    checks = []

    def add(check: str, bar: str, value: float | None, ok: Callable[[float], bool], shown: str = "") -> None:
        measured = value is not None
        checks.append({"check": check, "bar": bar, "value": value, "passed": measured and ok(value),
                       "shown": shown.format(value) if shown and measured else None})

    orbit = mean_coverage(runs, "orbit") if "orbit" in have else None
    add("mean coverage minus the tuned orbit's, points", f">= +{ORBIT_MARGIN:.1f}",
        overall - building_mean(orbit) if orbit else None, lambda v: v >= ORBIT_MARGIN)
    add("worst building minus the tuned orbit, points", f">= {ORBIT_WORST:+.1f}",
        min(mine[s] - orbit[s] for s in mine) if orbit else None, lambda v: v >= ORBIT_WORST)
    add(*_random_check(runs, mine, have))
    add("metres flown over the tuned orbit's", f"<= {FLIGHT_RATIO:.1f}x",
        mean_flight(runs, policy) / mean_flight(runs, "orbit") if orbit else None,
        lambda v: v <= FLIGHT_RATIO, "{:.2f}x")
    spreads = pair_spreads_m({scene: {r["seed"]: [Viewpoint(*v) for v in r["viewpoints"]] for r in by[policy]}
                              for scene, by in runs.items()}) if len(runs) > 1 else {}
    add("path spread, closest pair of buildings, m", f">= {SPREAD_M:.2f}",
        min(spreads.values()) if spreads else None, lambda v: v >= SPREAD_M, "{:.2f}")
    flown_blind = blank and all(policy in by for by in blank.values())
    blind = ("coverage lost with blank images, points", f">= {BLANK_DROP:.1f}")
    if reads_images:
        add(*blind, overall - building_mean(mean_coverage(blank, policy)) if flown_blind else None,
            lambda v: v >= BLANK_DROP)
    else:
        checks.append({"check": blind[0], "bar": blind[1], "value": None, "passed": None,
                       "shown": "does not apply (reads no image)"})
    if "orbit2" in have:
        checks.append({"check": "mean coverage minus the two tuned rings' (orbit2), points",
                       "bar": "reported", "value": overall - building_mean(mean_coverage(runs, "orbit2")),
                       "passed": None, "shown": None})
    return checks


def building_mean(by_building: Mapping[str, float]) -> float:
    """The mean over buildings of per-building values (`per_building`)."""
    return float(np.mean(list(by_building.values())))


def _random_check(runs: Runs, mine: dict[str, float], have: set[str]) -> tuple:
    """The check against random views on every building (held to the oracle where it is close to random):
    `add`'s arguments. Its value is the worst building held to the margin (the worst of all where the oracle
    clause excuses every one), so its `ok` is the margin."""
    check = (f"worst building minus random, points (or within {ORACLE_WITHIN:g} of an oracle under "
             f"{ORACLE_GAP:g} above random, an unrun oracle at most 100 %)")
    bar = f">= +{RANDOM_MARGIN:.1f}"
    if "random" not in have:
        return check, bar, None, lambda _: False
    rand = mean_coverage(runs, "random")
    oracle = mean_coverage(runs, "oracle") if "oracle" in have else {}
    gaps = {s: mine[s] - rand[s] for s in mine}
    held = [gap for s, gap in gaps.items() if not near_oracle(mine[s], rand[s], oracle.get(s))]
    return check, bar, min(held or gaps.values()), lambda v: not held or v >= RANDOM_MARGIN


def near_oracle(mine: float, rand: float, oracle: float | None) -> bool:
    """Whether the oracle clause excuses a building from the random margin: the oracle (`None`: not run,
    so anything up to 100 %) is under `ORACLE_GAP` points above random and `mine` within `ORACLE_WITHIN`
    of it."""
    bound = 100.0 if oracle is None else oracle
    return bound - rand < ORACLE_GAP and mine >= bound - ORACLE_WITHIN


def acceptance_checks(runs: Runs, blank: Runs | None, policies: Sequence[str],
                      depth: Sequence[str] = ()) -> dict[str, list[dict]]:
    """Every policy's checks (`policy_checks`), then every depth option's (reading no image), by label."""
    return ({policy: policy_checks(runs, blank, policy) for policy in policies}
            | {option: policy_checks(runs, blank, option, reads_images=False) for option in depth})


def acceptance_section(checks: Mapping[str, list[dict]], buildings: int,
                       depth: Sequence[str] = ()) -> list[str]:
    """The Markdown lines of the acceptance table: a row per check, a column per policy (the depth options'
    headed "(depth)")."""
    policies = list(checks)
    rows = [[c["check"], c["bar"], *(_cell(checks[p][i]) for p in policies)]
            for i, c in enumerate(checks[policies[0]])]
    rows.append(["**every check**", "", *(("**yes**" if passed == barred else "**no**")
                                          for passed, barred in map(tally, checks.values()))])
    return ["", f"## Acceptance (issue 26): each policy against the tuned orbit on {buildings} buildings", "",
            "Coverage of the true surface at the fixed budget, mean over seeds per building; metres along "
            "the viewing shell; path spread: mean distance between camera positions on two buildings from "
            "the same start view; blank images: the same runs with every captured image replaced by a blank "
            "one (`--blank`).", "", markdown_table(["check", "bar", *(f"{p} (depth)" if p in depth else p
                                                                 for p in policies)], rows)]


def tally(checks: Sequence[dict]) -> tuple[int, int]:
    """Of one policy's checks (`policy_checks`), how many with a bar pass, and how many have a bar (the
    reported ones have none)."""
    barred = [c for c in checks if c["passed"] is not None]
    return sum(c["passed"] for c in barred), len(barred)


def _cell(check: dict) -> str:
    if check["value"] is None:
        return "n/a (no)" if check["passed"] is not None else check["shown"]
    shown = check["shown"] or f"{check['value']:+.1f}"
    return shown if check["passed"] is None else f"{shown} ({'yes' if check['passed'] else 'no'})"
