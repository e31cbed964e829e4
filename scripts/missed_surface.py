"""Which true surface one planner's views see and another's miss, by how it faces (round 27's diagnostic).

Reads two planners' flights on one validation building from a `looks_eval` work folder (the viewpoints each
run flew, `WORK/NAME/SCENE.json`) or from studies' committed results (`--results`), and for every start view
scores them as the studies do: the samples of the target's true surface
(`nbv.recon.visibility.scene_visibility`, the same seed) that some view sees.
Each sample is told by its face's normal: a roof (pointing up), an outer wall (facing away from the
building's vertical axis), an inner wall (facing it: a courtyard's, a U's), or other. The table gives, per
start view, each planner's coverage, how many samples the baseline sees that the planner misses and the
reverse, with the share of each kind, median height and distance from the axis; `missed.png` draws, seen
from above, the samples the planner misses (red) and sees alone (blue) on the first start view.

    python scripts/missed_surface.py --work WORK --scene family:9 \
        --planner depth-teacher_r48_s4_w0.1_stereo --baseline orbit --out OUT
    python scripts/missed_surface.py --results paper_results/selection/round39/route_starts*/results.json \
        --scene family:39 --planner depth-teacher_r48_s4_w0.1_stereo_h13x2_fw_sd1_stp60b_rt \
        --baseline orbit2 --seeds 0 1 2 3 4 5 6 7 8 --out OUT
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import git_commit, portable_record
from nbv.recon.visibility import scene_visibility
from nbv.rl.presets import default_preset
from nbv.rl.validate import evaluation_env_config
from nbv.viz.figures import save_figure
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.spec import SceneSet

sys.path.insert(0, str(Path(__file__).parent))
import looks_eval  # noqa: E402

KINDS = ("roof", "outer wall", "inner wall", "other")
"""How a surface sample faces, in `facing`'s order."""
UP, SIDEWAYS = 0.7, 0.3
"""A roof's least normal z; a wall's least horizontal normal along (or against) the way out from the axis."""


def facing(points: np.ndarray, normals: np.ndarray, center: np.ndarray) -> np.ndarray:
    """Each sample's kind, an index into `KINDS`: a roof if its unit normal points up (z > `UP`), else an
    outer or inner wall if its normal's horizontal part points away from or towards the vertical axis
    through `center` (beyond `SIDEWAYS`), else other."""
    out = points[:, :2] - center[:2]
    out = out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-9)
    along = np.sum(normals[:, :2] * out, axis=1)
    return np.select([normals[:, 2] > UP, along > SIDEWAYS, along < -SIDEWAYS], [0, 1, 2], default=3)


def describe(mask: np.ndarray, kinds: np.ndarray, points: np.ndarray, center: np.ndarray) -> dict:
    """Of the samples in `mask`: their count, the share of each kind, their median height and median
    distance from the vertical axis through `center` (metres)."""
    chosen = points[mask]
    return {"count": int(mask.sum()),
            "kinds": {k: float(np.mean(kinds[mask] == i)) if mask.any() else 0.0
                      for i, k in enumerate(KINDS)},
            "median_z_m": float(np.median(chosen[:, 2])) if mask.any() else None,
            "median_radius_m": float(np.median(np.linalg.norm(chosen[:, :2] - center[:2], axis=1)))
            if mask.any() else None}


def compare(scene: str, flights: dict[str, dict], seeds: list[int], picture: Path) -> list[dict]:
    """Per start view, the two flights' coverage and the samples one sees and the other misses
    (`flights`: {"planner": runs, "baseline": runs}, runs by seed as a work folder keeps them)."""
    config = evaluation_env_config(default_preset().env, SceneSet(scene=(scene,)))
    target = config.scenes.specs()[0].load()
    normals, center = target.target_mesh().face_normals, target.center()
    rows = []
    for seed in seeds:
        visibility = scene_visibility(target, config.camera, seed=seed)
        points = visibility.samples
        kinds = facing(points, normals[visibility.faces], center)
        seen = {role: visibility.seen_by([viewpoint_to_c2w(Viewpoint(*view), center)
                                          for view in runs[str(seed)]["viewpoints"]])
                for role, runs in flights.items()}
        missed, alone = seen["baseline"] & ~seen["planner"], seen["planner"] & ~seen["baseline"]
        rows.append({"seed": seed, "coverage": {r: 100.0 * float(s.mean()) for r, s in seen.items()},
                     "missed": describe(missed, kinds, points, center),
                     "alone": describe(alone, kinds, points, center)})
        if seed == seeds[0]:
            draw(picture, points, missed, alone, scene, seed)
    return rows


def draw(path: Path, points: np.ndarray, missed: np.ndarray, alone: np.ndarray, scene: str,
         seed: int) -> None:
    """The samples seen from above: every one grey, those the planner misses red, those it sees alone blue."""
    fig = Figure(figsize=(5.5, 5.5))
    ax = fig.add_subplot()
    ax.scatter(points[:, 0], points[:, 1], s=0.3, c="0.8")
    ax.scatter(points[missed, 0], points[missed, 1], s=3, c="tab:red",
               label="the baseline sees, the planner misses")
    ax.scatter(points[alone, 0], points[alone, 1], s=3, c="tab:blue", label="the planner sees alone")
    ax.set(aspect="equal", xlabel="x (m)", ylabel="y (m)", title=f"{scene}, start view {seed}, from above")
    ax.legend(loc="upper right", fontsize=7)
    save_figure(fig, path)


def table(rows: list[dict]) -> str:
    """One line a start view: coverage of both, then the missed and the planner's own samples by kind."""
    def kinds(part: dict) -> str:
        return ", ".join(f"{k} {100 * v:.0f} %" for k, v in part["kinds"].items() if v >= 0.05)

    return markdown_table(
        ["start", "planner %", "baseline %", "baseline sees, planner misses", "kinds", "median z / radius m",
         "planner sees alone", "kinds", "median z / radius m"],
        [[r["seed"], f"{r['coverage']['planner']:.1f}", f"{r['coverage']['baseline']:.1f}",
          r["missed"]["count"], kinds(r["missed"]), where(r["missed"]), r["alone"]["count"],
          kinds(r["alone"]), where(r["alone"])] for r in rows])


def where(part: dict) -> str:
    """Median height and distance from the axis, as the table writes them."""
    return "-" if part["median_z_m"] is None else f"{part['median_z_m']:.2f} / {part['median_radius_m']:.2f}"


def worked(work: Path, name: str, scene: str) -> dict:
    """One planner's runs on `scene` by start view, from a `looks_eval` work folder."""
    saved = looks_eval.work_file(work, name, scene)
    if not saved.is_file():
        raise SystemExit(f"no flights of {name} on {scene} in {work} ({saved.name} missing)")
    return json.loads(saved.read_text())["result"]["runs"]


def studied(files: list[Path], name: str, scene: str) -> dict:
    """One planner's runs on `scene` by start view, merged from studies' results.json (`write_study`)."""
    runs = {}
    for path in files:
        doc = json.loads(path.read_text())["results"].get(name, {}).get("runs", {})
        runs |= doc.get(scene, {}).get("runs", {})
    if not runs:
        raise SystemExit(f"no flights of {name} on {scene} in {', '.join(map(str, files))}")
    return runs


def flight_arguments(parser: argparse.ArgumentParser, baseline: str) -> None:
    """The options of a diagnostic comparing two planners' flights on one building (`baseline`: default)."""
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--work", type=Path, help="a looks_eval work folder")
    source.add_argument("--results", type=Path, nargs="+",
                        help="instead, studies' results.json files (their start views merged)")
    parser.add_argument("--scene", required=True)
    parser.add_argument("--planner", required=True, help="the planner's name in the work folder")
    parser.add_argument("--baseline", default=baseline)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4, 5])
    parser.add_argument("--out", type=Path, required=True)


def read_flights(args: argparse.Namespace) -> dict[str, dict]:
    """The planner's and the baseline's runs (`flight_arguments`), by role; held-out buildings refused."""
    looks_eval.refuse_held_out([args.scene])
    return {role: (studied(args.results, name, args.scene) if args.results
                   else worked(args.work, name, args.scene))
            for role, name in (("planner", args.planner), ("baseline", args.baseline))}


def command_record(args: argparse.Namespace) -> dict:
    """The command line as a results file records it: each option's value, lists space-separated."""
    return portable_record({k: " ".join(map(str, v)) if isinstance(v, list) else str(v)
                            for k, v in vars(args).items()})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    flight_arguments(parser, "orbit")
    args = parser.parse_args()
    flights = read_flights(args)
    with atomic_folder(args.out, overwrite=True, outputs=("results.json", "results.md", "missed.png")) as out:
        rows = compare(args.scene, flights, args.seeds, out / "missed.png")
        text = table(rows)
        record = {"command": command_record(args), "commit": git_commit(), "rows": rows}
        write_json(out / "results.json", record)
        write_text(out / "results.md", f"# What {args.planner} misses of what {args.baseline} sees on "
                   f"{args.scene}\n\nSamples of the true surface (of 20000) by start view.\n\n{text}\n"
                   "![from above](missed.png)\n")
    print(text)


if __name__ == "__main__":
    main()
