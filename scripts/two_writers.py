"""Two `nbv scan` runs started at the same moment on one fresh `--out`, N times (issue 28): each trial
passes when exactly one run succeeds, the other fails with a named one-line error (the other run's pid,
or the output it found), and `--out` holds the winner's complete dataset with nothing beside it.

    python scripts/two_writers.py --trials 10 --views 4 --scratch /tmp/two-writers
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

from render.dataset import read_dataset

ROOT = Path(__file__).resolve().parents[1]
CAMERA = ["--width", "64", "--height", "48", "--spp", "1"]


def start(out: Path, views: int, seed: int) -> subprocess.Popen:
    """`nbv scan test_building circle` of `views` views into `out`, in the background."""
    command = [sys.executable, "-m", "nbv.cli", "scan", "test_building", "circle", "--views", str(views),
               "--seed", str(seed), *CAMERA, "--out", str(out)]
    return subprocess.Popen(command, env={**os.environ, "PYTHONPATH": str(ROOT)}, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)


def trial(out: Path, views: int) -> str:
    """One trial; returns 'ok: ...' or 'FAIL: ...'."""
    runs = [start(out, views, 5), start(out, views + 1, 7)]
    done = [(run.wait(), run.stderr.read().strip().splitlines()) for run in runs]
    winners = [i for i, (rc, _) in enumerate(done) if rc == 0]
    if len(winners) != 1:
        return f"FAIL: {len(winners)} runs succeeded"
    loser = 1 - winners[0]
    rc, lines = done[loser]
    last = lines[-1] if lines else ""
    busy = f"is being written by another run (pid {runs[winners[0]].pid})"
    if rc != 2 or not last.startswith("nbv scan: error: ") or not (busy in last or "exists" in last):
        return f"FAIL: the other run ended {rc}: {last!r}"
    if any("Traceback" in line for line in lines):
        return "FAIL: a traceback"
    frames = len(read_dataset(out))
    stray = [p.name for p in out.parent.iterdir() if p.name != out.name]
    if frames != views + winners[0] or stray:
        return f"FAIL: {frames} frames, beside it {stray}"
    return f"ok: run {winners[0] + 1} won; the other: {'busy' if busy in last else 'exists'}"


def main() -> None:
    """Run the trials and print one line each and the count."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=10, help="how many trials")
    parser.add_argument("--views", type=int, default=4, help="views of the first scan (the second: one more)")
    parser.add_argument("--scratch", type=Path, default=Path("/tmp/two-writers"), help="a folder to work in")
    args = parser.parse_args()
    passed = 0
    for i in range(args.trials):
        folder = args.scratch / f"trial{i}"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        result = trial(folder / "same", args.views)
        passed += result.startswith("ok")
        print(f"trial {i + 1}: {result}", flush=True)
    print(f"{passed}/{args.trials} trials: exactly one complete dataset and the other run's named error")


if __name__ == "__main__":
    main()
