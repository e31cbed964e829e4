"""Coverage against metres over selection rounds: every scored actor's gain over the tuned ring and its
metres as a multiple of the ring's, against issue 26's two bars (+3 points, 1.5x), from the results files
of `scripts/looks_eval.py` and `scripts/teacher_eval.py` (validation buildings only, as they are).

Each `--results GROUP=PATH` is one such `results.json`; a planner scored in several files (the shipped
actor, the baselines) is taken from the first that has it. An actor "looks" where blank images cost it at
least 3 points (the looks check's bar). Writes `frontier.md` (every actor, and per group how many sit
inside both bars and how many look) and `frontier.png`. `--axis worst` draws and counts the worst
building's gain over the ring against its bar (-1 point) instead of the mean's (round 30's look-ahead
settings).

    python scripts/selection_frontier.py \
        --results "default=paper_results/selection/round21/seed2/results.json" \
        --results "hinge=paper_results/selection/round22/hinge_seed1/results.json" --out OUT
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from matplotlib.figure import Figure

from common.io import atomic_folder, markdown_table, write_text
from nbv.experiments.online_acceptance import (
    BLANK_DROP,
    FLIGHT_RATIO,
    ORBIT_MARGIN,
    ORBIT_WORST,
    building_mean,
)
from nbv.viz.figures import save_figure

REFERENCE = "orbit"
"""The tuned single ring every gain and metres ratio is taken against."""
BASELINES = ("orbit", "orbit2", "random")
"""Fixed planners, drawn once and labelled, not counted in a group."""
AXES = {"gain": (ORBIT_MARGIN, "mean coverage over the tuned ring, points"),
        "worst": (ORBIT_WORST, "worst building's coverage over the tuned ring, points")}
"""What the vertical axis may be: each point's field, its bar (issue 26's) and its label."""


def frontier_points(files: list[tuple[str, dict]], exclude: tuple[str, ...] = ()) -> list[dict]:
    """One point per planner (first file that has it, none of `exclude`): its group, name, gain over the
    ring (points), its worst building's gain, metres over the ring's, and blank drop (points, None without
    blank flights)."""
    points, seen = [], set(exclude)
    for group, doc in files:
        ring = doc["results"][REFERENCE]["summary"]
        ring_cover, ring_metres = building_mean(ring["coverage"]), building_mean(ring["flight_m"])
        for name, result in doc["results"].items():
            if name in seen:
                continue
            seen.add(name)
            summary = result["summary"]
            cover = building_mean(summary["coverage"])
            blank = summary.get("blank")
            metres = building_mean(summary["flight_m"])
            points.append({"group": "baseline" if name in BASELINES else group, "name": name,
                           "gain": cover - ring_cover, "ratio": metres / ring_metres,
                           "worst": min(summary["coverage"][s] - c for s, c in ring["coverage"].items()),
                           "drop": cover - building_mean(blank) if blank else None})
    return points


def inside(point: dict, axis: str = "gain") -> bool:
    """Whether a point passes both `axis`'s bar (`AXES`) and the metres bar
    (`nbv.experiments.online_acceptance`'s)."""
    return point[axis] >= AXES[axis][0] and point["ratio"] <= FLIGHT_RATIO


def looks(point: dict) -> bool:
    """Whether blank images cost the point's planner at least the looks check's bar."""
    return point["drop"] is not None and point["drop"] >= BLANK_DROP


def groups_of(points: list[dict]) -> list[str]:
    """The points' groups in their first order, the baselines left out."""
    return list(dict.fromkeys(p["group"] for p in points if p["group"] != "baseline"))


def report(points: list[dict], axis: str = "gain") -> str:
    """The groups' counts, then every point (markdown); inside: `axis`'s bar and the metres bar."""
    counts = []
    for group in groups_of(points):
        mine = [p for p in points if p["group"] == group]
        counts.append([group, len(mine), sum(inside(p, axis) for p in mine), sum(map(looks, mine)),
                       sum(inside(p, axis) and looks(p) for p in mine)])
    rows = [[p["group"], p["name"], f"{p['gain']:+.2f}", f"{p['worst']:+.2f}", f"{p['ratio']:.2f}x",
             "-" if p["drop"] is None else f"{p['drop']:.1f}", "yes" if inside(p, axis) else "no"]
            for p in points]
    head = ["group", "planner", "vs orbit", "worst vs orbit", "metres", "blank drop", "inside"]
    bar, label = AXES[axis]
    return (f"Validation buildings, 13 views: mean coverage over the tuned ring (`{REFERENCE}`), the worst "
            f"building's, and metres over its metres; inside: {label} at least {bar:+g} within "
            f"{FLIGHT_RATIO:g}x; looks: blank images cost at least {BLANK_DROP:g} points.\n\n"
            + markdown_table(["group", "actors", "inside both bars", "look", "inside and look"], counts)
            + "\n\n" + markdown_table(head, rows) + "\n")


def plot(points: list[dict], out: Path, axis: str = "gain") -> Path:
    """`axis` (`AXES`) against metres ratio, one colour per group, filled where the actor looks (a cross:
    no blank flights); the baselines starred; the bars dashed."""
    fig = Figure(figsize=(7.5, 5.0))
    ax = fig.subplots()
    kinds = {  # what a point is, and how it is drawn in its group's colour
        "looks": (looks, lambda colour: {"facecolors": colour}),
        f"blank costs < {BLANK_DROP:g} points": (
            lambda p: p["drop"] is not None and not looks(p),
            lambda colour: {"facecolors": "none", "edgecolors": colour}),
        "no blank flights": (lambda p: p["drop"] is None, lambda colour: {"marker": "x", "c": colour})}
    for i, group in enumerate(groups_of(points)):
        for kind, (test, style) in kinds.items():
            mine = [p for p in points if p["group"] == group and test(p)]
            ax.scatter([p["ratio"] for p in mine], [p[axis] for p in mine], s=28,
                       label=f"{group} ({kind})" if mine else None, **style(f"C{i}"))
    for p in points:
        if p["group"] == "baseline":
            ax.plot(p["ratio"], p[axis], "k*", markersize=10)
            ax.annotate(p["name"], (p["ratio"], p[axis]), textcoords="offset points", xytext=(5, 4),
                        fontsize=8)
    bar, label = AXES[axis]
    ax.axhline(bar, color="grey", linestyle="--")
    ax.axvline(FLIGHT_RATIO, color="grey", linestyle="--")
    ratios = [p["ratio"] for p in points]
    ax.set_xlim(min(0.9, min(ratios) - 0.05), max(2.0, min(4.2, max(ratios) + 0.1)))
    ax.set_xlabel(f"metres over the tuned ring's (bar {FLIGHT_RATIO:g}x)")
    ax.set_ylabel(f"{label} (bar {bar:+g})")
    ax.set_title("Selection rounds on validation buildings: coverage against flight")
    ax.legend(fontsize=7, loc="lower right")
    return save_figure(fig, out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", action="append", required=True, metavar="GROUP=PATH")
    parser.add_argument("--exclude", nargs="*", default=[], help="planners left out (another setting's)")
    parser.add_argument("--axis", choices=tuple(AXES), default="gain",
                        help="the vertical axis: the mean's gain over the ring or the worst building's")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    files = [(group, json.loads(Path(path).read_text()))
             for group, path in (item.split("=", 1) for item in args.results)]
    points = frontier_points(files, tuple(args.exclude))
    table = report(points, args.axis)
    with atomic_folder(args.out, overwrite=True, outputs=("frontier.md", "frontier.png")) as out:
        write_text(out / "frontier.md", table + "\nCommand: `python scripts/selection_frontier.py "
                   + " ".join(f'--results "{r}"' for r in args.results)
                   + "".join(f" --exclude {name}" for name in args.exclude)
                   + (f" --axis {args.axis}" if args.axis != "gain" else "") + " --out OUT`\n")
        plot(points, out / "frontier.png", args.axis)
    print(table)


if __name__ == "__main__":
    sys.exit(main())
