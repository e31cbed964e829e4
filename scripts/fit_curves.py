"""How well students fit their teacher, pass by pass: the held-out curves of `scripts/dagger.py` and
`scripts/score_student.py` side by side (issue 26, round 23; validation of the training, not of flights).

Each `--dagger NAME=PATH` is a `dagger.json`: its seed-state fit's held-out loss per pass (the squared
distance between the actor's mode and the teacher's action, summed over the three values). Each
`--ranking NAME=PATH` is a `fit.json` of `score_student.py`: its held regret per pass (the teacher's best
score less the score of the student's choice, coverage points a step), its rounds one after another.
Writes `fit_curves.png` (one panel each) and `fit_curves.md` (each curve's best value and where).

    python scripts/fit_curves.py --dagger "with the map=ROUND23/fit_privileged/dagger.json" \
        --ranking "captured=ROUND23/ranking_capture/fit.json" --out OUT
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from matplotlib.figure import Figure

from common.io import atomic_folder, markdown_table, write_text
from nbv.viz.figures import save_figure


def dagger_curve(doc: dict) -> list[float]:
    """The held-out loss per pass of a `dagger.json`'s fit to its seed states (the buffers' round)."""
    fitted = next(it for it in doc["iterations"] if it["iteration"] == "buffers")
    return [p["held"] for p in fitted["passes"]]


def ranking_curve(doc: dict) -> list[float]:
    """The held regret per pass of a `score_student.py` `fit.json`, its rounds one after another."""
    return [p["held_regret"] for fitted in doc["rounds"] for p in fitted["passes"]]


def named(specs: list[str]) -> list[tuple[str, dict]]:
    """`NAME=PATH` arguments as (name, the JSON document)."""
    pairs = []
    for spec in specs:
        name, _, path = spec.partition("=")
        if not path:
            raise SystemExit(f"expected NAME=PATH, got {spec!r}")
        pairs.append((name, json.loads(Path(path).read_text())))
    return pairs


def best_rows(kind: str, curves: list[tuple[str, list[float]]]) -> list[list[str]]:
    """One table row per curve: its kind, name, first, best (and the pass) and last value."""
    return [[kind, name, f"{c[0]:.2f}", f"{min(c):.2f} ({c.index(min(c)) + 1})", f"{c[-1]:.2f}"]
            for name, c in curves]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dagger", action="append", default=[], metavar="NAME=PATH")
    parser.add_argument("--ranking", action="append", default=[], metavar="NAME=PATH")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    panels = [("imitation fit: held-out loss", "squared distance to the teacher's action",
               [(n, dagger_curve(d)) for n, d in named(args.dagger)]),
              ("ranking student: held regret", "coverage points a step",
               [(n, ranking_curve(d)) for n, d in named(args.ranking)])]
    panels = [panel for panel in panels if panel[2]]
    if not panels:
        raise SystemExit("give at least one --dagger or --ranking file")
    fig = Figure(figsize=(5.5 * len(panels), 4.0))
    for i, (title, ylabel, curves) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1)
        for name, curve in curves:
            ax.plot(range(1, len(curve) + 1), curve, marker=".", label=name)
        ax.set(title=title, xlabel="pass over the pooled states", ylabel=ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small")
    fig.tight_layout()
    rows = [row for title, _, curves in panels for row in best_rows(title.split(":")[0], curves)]
    table = markdown_table(["fit", "curve", "first", "best (pass)", "last"], rows)
    command = " ".join(f'"{a}"' if " " in a else a for a in ["python", "scripts/fit_curves.py", *argv])
    with atomic_folder(args.out, overwrite=True, outputs=("fit_curves.md", "fit_curves.png")) as out:
        save_figure(fig, out / "fit_curves.png")
        write_text(out / "fit_curves.md", f"{table}\nCommand: `{command}`\n")
    print(table)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
