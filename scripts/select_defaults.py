"""Choose `nbv train`'s defaults by validation performance (issue 11): candidates x training seeds.

Each candidate is the shared base command plus its flags; every (candidate, seed) run trains on the
training buildings (`TRAIN_SCENES`) and is scored on validation buildings that no run trains on
(`VALIDATION_SCENES`: training-split `random:SEED` buildings; the test buildings alpine_chalet,
imperial_temple and random:SEED with SEED % 5 == 0 are never touched here). The score is the policy's
mode over `--episodes` start views per building, rendered at exact viewpoints, scored by the
visible-surface coverage of the true mesh (`nbv.planning.selection.validation_score`, the library's
model-selection score). This script keeps the rounds' candidates and runs them.

    python scripts/select_defaults.py train --round 2 --runs runs/selection --frames 6000 --jobs 3
    python scripts/select_defaults.py score --runs runs/selection --out paper_results/selection

(round 1, before the lattice fix: `train --round 1 --frames 4000`; its results, measured on a tree with
uncommitted changes, left paper_results and stay in the git history at f32fc04.)
"""

from __future__ import annotations

import argparse
import itertools
import json
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from tqdm import tqdm

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import git_commit
from nbv.planning.config import PlanSettings
from nbv.planning.policy import PolicyPlanner
from nbv.planning.registry import make_planner
from nbv.planning.selection import validation_score
from nbv.rl.presets import TRAIN_SCENES, VALIDATION_SCENES
from nbv.viz.figures import plot_seed_scores

BASE = ("--preset", "paper", "--width", "160", "--height", "120", "--spp", "4", "--feature-backend", "opencv",
        "--lattice", "--relative-step", "0.125", "--threads", "1", "--no-progress")
CANDIDATES = {
    "orbit": ("--action-mode", "orbit", "--reward-scale", "0.1"),
    "absolute": ("--action-mode", "absolute", "--reward-scale", "0.1"),
    "relative": ("--action-mode", "relative", "--reward-scale", "0.1"),
    "orbit-alpha0.2": ("--action-mode", "orbit", "--reward-scale", "1"),
    "orbit-auto-alpha": ("--action-mode", "orbit", "--reward-scale", "1", "--auto-alpha"),
    "orbit-bands2": ("--action-mode", "orbit", "--reward-scale", "0.1", "--elevation-bands", "2"),
    "relative-bands2": ("--action-mode", "relative", "--reward-scale", "0.1", "--elevation-bands", "2"),
}
"""Round 1, flags over the paper preset (Table 1), one factor at a time from `orbit` (the best design measured
before): the action mode (absolute is the paper's), the entropy setting (fixed alpha 0.2 on raw rewards as in
Table 1, or learned), and the Bag of Views ranges split into two elevation bands; then the two best factors
together (`relative-bands2`, added once the first seeds of the others were scored). Measured before the
lattice fix (a snapped viewpoint kept small relative steps from moving the camera); each run keeps its last
actor."""
BASE2 = ("--preset", "default", "--members", "1", "--threads", "1", "--no-progress")
BASE_BOV = (*BASE2, "--coverage-reward", "0")
"""Rounds 2 and 3 ran before the default had a coverage term: the default preset without it."""
CANDIDATES2 = {
    "one-pass": ("--episode-views", "0"),
    "views13": ("--episode-views", "13"),
    "orbit-views13": ("--episode-views", "13", "--action-mode", "orbit"),
    "views13-step0.25": ("--episode-views", "13", "--relative-step", "0.25"),
}
"""Round 2, after the lattice fix, flags over the default preset (`relative-bands2`, each checkpoint
validated, `policy.pt` the best), one training seed per run (`--members 1`): episodes of one pass (the
paper) or of 13 views (the evaluation's budget); then, after views13 was chosen and evaluated, orbit
actions with 13-view episodes (absolute R and elevation: a start elevation cannot linger) and relative
steps twice as long, against the seed spread views13 showed."""
CANDIDATES3 = {
    "batch32": ("--batch-size", "32", "--updates-per-frame", "0.3"),
    "lr2e-4": ("--lr", "2e-4"),
}
"""Round 3, after the default's members were evaluated (paper_results/selection/members: two of nine
seeds good), against the seed-to-seed variance itself, over round 2's base and views13: batches of 32
instead of Table 1's 8 at a third of the gradient steps (3 per 10 frames: about the same compute, less
gradient noise); then, as batch32 and the default both peaked and fell back, a learning rate of 2e-4
instead of 5e-4."""
CANDIDATES4 = {
    "cov100": ("--coverage-reward", "100"),
    "cov300": ("--coverage-reward", "300"),
}
"""Round 4, after round 3 and a look at the members' modes (each flies one helix at the largest azimuth
step; the seeds differ in where R and elevation drift, which the Bag of Views reward ignores), over
round 2's base and views13: a geometric term added to the reward (`--coverage-reward W`: W x the share
of the true surface a view is the episode's first to see; beyond the paper), at two weights. An
episode's Bag of Views return is about 105-130 and its coverage about 0.8, so W = 100 adds a term of
about the same size and W = 300 one that dominates."""
ROUNDS = {1: (BASE, CANDIDATES), 2: (BASE_BOV, CANDIDATES2), 3: (BASE_BOV, CANDIDATES3),
          4: (BASE2, CANDIDATES4)}
"""`--round N`: the base command and candidates of each selection round."""


def train_one(run: Path, flags: tuple[str, ...], seed: int, frames: int, round_: int) -> float:
    """Train one run (resumes a finished or partial one); return its wall time in seconds."""
    scenes = [arg for scene in TRAIN_SCENES for arg in ("--scene", scene)]
    # Round 1 checkpointed once, at the end; round 2 keeps the preset's cadence (each checkpoint validated).
    every = ("--checkpoint-every", str(frames)) if round_ == 1 else ()
    command = ["nbv", "train", *scenes, *ROUNDS[round_][0], *flags, "--seed", str(seed),
               "--frames", str(frames), *every, "--out", str(run)]
    start = time.perf_counter()
    run.mkdir(parents=True, exist_ok=True)
    with open(run / "train.log", "a") as log:
        subprocess.run(command, check=True, stdout=log, stderr=subprocess.STDOUT)
    return time.perf_counter() - start


def train_all(args: argparse.Namespace) -> None:
    """Every candidate x seed, `--jobs` at a time (seeds interleaved, so a cut run still compares)."""
    candidates = ROUNDS[args.round][1]
    unknown = sorted(set(args.candidates or ()) - set(candidates))
    if unknown:
        raise SystemExit(f"not candidates of round {args.round}: {', '.join(unknown)}")
    jobs = [(name, seed) for seed, name in itertools.product(args.seeds, args.candidates or candidates)]
    with ThreadPoolExecutor(args.jobs) as pool:
        futures = {pool.submit(train_one, args.runs / f"{name}-seed{seed}", candidates[name], seed,
                               args.frames, args.round): (name, seed) for name, seed in jobs}
        for future, (name, seed) in futures.items():
            print(f"{name} seed {seed}: {future.result():.0f} s", flush=True)


def score_all(args: argparse.Namespace) -> None:
    """Score every finished run and the random and circle baselines; write selection.{json,md,png}."""
    runs = sorted(p.parent for p in args.runs.glob("*-seed*/policy.pt"))
    scores: dict[str, dict[int, float]] = {}
    env_config = None
    for run in tqdm(runs, desc="score runs", unit="run"):
        name, seed = run.name.rsplit("-seed", 1)
        planner = PolicyPlanner(run / "policy.pt")  # the actor the run chose (without validation: the last)
        env_config = planner.env_config
        key = {"views": args.views, "episodes": args.episodes, "scenes": list(VALIDATION_SCENES),
               "frames": json.loads((run / "config.json").read_text())["collector"]["frames"]}
        saved = run / "validation.json"  # a run's score, kept while the protocol and its budget hold
        if saved.is_file() and json.loads(saved.read_text())["key"] == key:
            score = json.loads(saved.read_text())["score"]
        else:
            score = validation_score(planner, env_config, VALIDATION_SCENES, args.views, args.episodes)
            write_json(saved, {"key": key, "score": score})
        scores.setdefault(name, {})[int(seed)] = score
    baselines = {name: validation_score(make_planner(name, PlanSettings(), seed=0), env_config,
                                        VALIDATION_SCENES, args.views, args.episodes)
                 for name in ("random", "circle")}
    seeds = sorted({seed for by_seed in scores.values() for seed in by_seed})
    rows = [[name, len(by_seed), *(f"{by_seed[s]:.1f}" if s in by_seed else "-" for s in seeds),
             f"{np.mean(list(by_seed.values())):.1f} ± {np.std(list(by_seed.values())):.1f}"]
            for name, by_seed in sorted(scores.items(), key=lambda kv: -np.mean(list(kv[1].values())))]
    table = (f"Visible-surface coverage (%) of the true mesh, policy mode, {args.views} views, validation "
             f"buildings {', '.join(VALIDATION_SCENES)} x {args.episodes} start views; "
             + ", ".join(f"{k} {v:.1f}" for k, v in baselines.items()) + "\n\n"
             + markdown_table(["candidate", "seeds", *(f"seed {i}" for i in seeds), "mean ± std"],
                              rows))
    outputs = ("selection.json", "selection.md", "selection.png")
    with atomic_folder(args.out, overwrite=True, outputs=outputs) as out:
        write_text(out / "selection.md", table)
        plot_seed_scores({k: list(v.values()) for k, v in scores.items()}, out / "selection.png",
                         "visible coverage % (validation)", "nbv train candidates", baselines)
        write_json(out / "selection.json", {
            "commit": git_commit(), "train_scenes": TRAIN_SCENES, "validation_scenes": VALIDATION_SCENES,
            "views": args.views, "episodes": args.episodes, "rounds": ROUNDS,
            "scores": scores, "baselines": baselines,
            "frames": {run.name: json.loads((run / "config.json").read_text())["collector"]["frames"]
                       for run in runs}})
    print(table)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    train = sub.add_parser("train")
    train.add_argument("--runs", type=Path, required=True)
    train.add_argument("--frames", type=int, default=4000)
    train.add_argument("--jobs", type=int, default=2)
    train.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    train.add_argument("--round", type=int, default=2, choices=list(ROUNDS))
    train.add_argument("--candidates", nargs="+",
                       choices=[name for _, names in ROUNDS.values() for name in names],
                       help="default: every candidate of the round")
    score = sub.add_parser("score")
    score.add_argument("--runs", type=Path, required=True)
    score.add_argument("--out", type=Path, required=True)
    score.add_argument("--views", type=int, default=13)
    score.add_argument("--episodes", type=int, default=3)
    args = parser.parse_args()
    if args.command == "train":
        train_all(args)
    else:
        score_all(args)


if __name__ == "__main__":
    sys.exit(main())
