"""SIGKILL `nbv train` at random moments, resume it, and compare with a run that went through (issue 28).

A trial starts the command in a fresh process (its own process group, as a
shell would start it; a forkserver child that skips the imports, or with
`--exec` a `python -m nbv.cli train` process), kills the group with SIGKILL
once or twice, each at a uniform random time into the run's training (0 to
the uninterrupted run's training time after the process opened or cut back
its log: before and after the first checkpoint), runs the same command again
to the end, and compares the run folder with the uninterrupted run's: every
tensor and value of `checkpoint.pt` (weights, optimisers, replay buffer,
counters, random states, the env's snapshot; the recorded `--out` aside), the
actor and counters of `policy.pt`, `metrics.csv` without its timing columns,
and `validation.csv`. The settings are tiny (`ARGS`: 64x48 renders at 1 spp,
tiny networks, a 1x8x2 lattice for the default preset).

    PYTHONPATH=. python scripts/kill_resume.py --preset paper --trials 10 --out /tmp/kills

prints one line per trial and `passed N/T (K kills)`; it exits 1 unless all passed.
`tests/nbv/rl/test_kill_resume.py` kills at fixed moments in `make test`.
"""

from __future__ import annotations

import argparse
import csv
import json
import multiprocessing
import os
import random
import runpy
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
TINY = ["--scene", "test_building", "--width", "64", "--height", "48", "--spp", "1", "--obs-size", "16",
        "--history", "2", "--max-steps", "6", "--feature-backend", "opencv", "--max-features", "50",
        "--channels", "4", "--hidden", "16", "--location-hidden", "8", "--batch-size", "4",
        "--buffer-size", "1000", "--frames", "40", "--frames-per-batch", "4", "--init-random-frames", "8",
        "--checkpoint-every", "12", "--threads", "1", "--workers", "1", "--members", "1", "--no-progress"]
ARGS = {
    "paper": ["--preset", "paper", *TINY],
    "default": ["--preset", "default", *TINY, "--episode-views", "5", "--lattice-radii", "1",
                "--lattice-azimuths", "8", "--lattice-elevations", "2", "--validation-scenes",
                "test_building", "--validation-episodes", "1", "--validation-views", "3",
                "--validation-points", "500"],
}
"""`nbv train` arguments of each preset (without `--out`): 40 frames, checkpoints at 12, 24, 36 and 40."""
TIMING = ("collect_s", "update_s")
"""The wall-clock columns of metrics.csv, the only ones a resumed run may log differently."""
POLL_S = 0.005


def launch(preset: str, out: Path) -> subprocess.Popen:
    """Start `nbv train` for `preset` into `out` in its own process group (output to `out`.log)."""
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    env = {**os.environ, "PYTHONPATH": path}
    log = open(out.with_name(out.name + ".log"), "ab")
    return subprocess.Popen([sys.executable, "-m", "nbv.cli", "train", *ARGS[preset], "--out", str(out)],
                            cwd=ROOT, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)


def forked(preset: str, out: Path) -> Forked:
    """Start `nbv train` for `preset` into `out` as a child of the forkserver (`preload_forkserver`): a
    fresh process, in its own process group, that skips the seconds of imports."""
    process = multiprocessing.get_context("forkserver").Process(target=_train_child, args=(preset, out))
    process.start()
    return Forked(process)


def preload_forkserver() -> None:
    """Start the forkserver now, importing `nbv train`'s modules (none that starts a thread)."""
    from multiprocessing import forkserver

    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["nbv.cli", "nbv.cli.train", "nbv.rl.command", "scripts.kill_resume"])
    forkserver.ensure_running()


class Forked:
    """A forkserver child as `subprocess.Popen` shows a process: `pid`, `poll()`, `wait()`."""

    def __init__(self, process: multiprocessing.Process) -> None:
        self._process = process
        self.pid = process.pid

    def poll(self) -> int | None:
        """The exit status, None while it runs."""
        return self._process.exitcode

    def wait(self) -> int:
        """Wait for the end; the exit status."""
        self._process.join()
        return self._process.exitcode


def _train_child(preset: str, out: Path) -> None:
    os.setsid()
    log = os.open(out.with_name(out.name + ".log"), os.O_WRONLY | os.O_CREAT | os.O_APPEND)
    os.dup2(log, 1)
    os.dup2(log, 2)
    sys.argv = ["nbv", "train", *ARGS[preset], "--out", str(out)]
    runpy.run_module("nbv.cli", run_name="__main__", alter_sys=True)  # as `python -m nbv.cli`: it exits


def finish(preset: str, out: Path, start: Callable = launch) -> None:
    """Run `nbv train` for `preset` into `out` to the end (`start`: `launch` or `forked`)."""
    if start(preset, out).wait() != 0:
        raise RuntimeError(f"nbv train {preset} into {out} failed: see {out}.log")


def kill_when(process: subprocess.Popen | Forked, moment: Callable[[], bool],
              timeout_s: float = 600.0) -> bool:
    """SIGKILL the process group as soon as `moment()` is true; False if the process ended first."""
    deadline = time.monotonic() + timeout_s
    while process.poll() is None and time.monotonic() < deadline:
        if moment():
            try:
                os.killpg(process.pid, signal.SIGKILL)
            except ProcessLookupError:  # a forked child not yet its own group's leader
                os.kill(process.pid, signal.SIGKILL)
            process.wait()
            return True
        time.sleep(POLL_S)
    if process.poll() is None:
        raise TimeoutError(f"nbv train did not reach the kill moment in {timeout_s} s")
    return False


def before_first_checkpoint(out: Path) -> Callable[[], bool]:
    """The moment the run has opened metrics.csv, still empty (its header buffered), and written no
    checkpoint."""
    log = out / "metrics.csv"
    return lambda: log.exists() and log.stat().st_size == 0 and not (out / "checkpoint.pt").exists()


def at_second_log_flush(out: Path) -> Callable[[], bool]:
    """The moment metrics.csv grows after the first checkpoint: the second checkpoint's log is on disk, its
    checkpoint.pt not yet (the probe's F10 window)."""
    first: list[int] = []

    def moment() -> bool:
        if not (out / "checkpoint.pt").exists():
            return False
        size = (out / "metrics.csv").stat().st_size
        first.extend([] if first else [size])
        return size > first[0]
    return moment


def into_the_run(out: Path, delay_s: float) -> Callable[[], bool]:
    """The moment `delay_s` after the run started training: after it opened metrics.csv (a new run) or cut
    it back to its checkpoint (a resumed one), i.e. past its start-up."""
    since, opened = time.time(), []

    def moment() -> bool:
        if not opened:
            log = out / "metrics.csv"
            if log.exists() and log.stat().st_mtime >= since:
                opened.append(time.monotonic())
            return False
        return time.monotonic() - opened[0] >= delay_s
    return moment


def differences(a: Path, b: Path) -> list[str]:
    """What differs between two run folders (empty: equal), see the module docstring."""
    out = []
    for name in ("checkpoint.pt", "policy.pt"):
        sa, sb = (torch.load(run / name, map_location="cpu", weights_only=True) for run in (a, b))
        sa["config"], sb["config"] = (_without_out(s["config"]) for s in (sa, sb))
        out += [f"{name}{where}" for where in _diff(sa, sb)]
    for name in ("metrics.csv", "validation.csv"):
        if _rows(a / name) != _rows(b / name):
            out.append(name)
    return out


def _without_out(config: str) -> dict:
    record = json.loads(config)
    record["logger"].pop("out")
    return record


def _rows(path: Path) -> list[dict] | None:
    if not path.exists():
        return None
    with open(path, newline="") as file:
        return [{k: v for k, v in row.items() if k not in TIMING} for row in csv.DictReader(file)]


def _diff(a, b, where: str = "") -> list[str]:
    if type(a) is not type(b):
        return [where]
    if isinstance(a, dict):
        if a.keys() != b.keys():
            return [f"{where} keys"]
        return [d for key in a for d in _diff(a[key], b[key], f"{where}.{key}")]
    if isinstance(a, list | tuple):
        if len(a) != len(b):
            return [f"{where} length"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _diff(x, y, f"{where}[{i}]")]
    if isinstance(a, torch.Tensor):
        same = a.shape == b.shape and a.dtype == b.dtype and torch.equal(a, b)
        nan_same = same or (a.is_floating_point() and torch.allclose(a, b, 0, 0, equal_nan=True))
        return [] if nan_same else [where]
    return [] if a == b else [where]


def stage(out: Path) -> str:
    """Where a killed run stood: before its first checkpoint, or after the checkpoint at N frames."""
    if not (out / "checkpoint.pt").exists():
        size = (out / "metrics.csv").stat().st_size if (out / "metrics.csv").exists() else None
        return f"before the first checkpoint (metrics.csv {size} bytes)"
    frames = torch.load(out / "checkpoint.pt", weights_only=True)["counters"]["frames"]
    return f"after the checkpoint at {frames} frames"


def trial(preset: str, reference: Path, out: Path, train_s: float, rng: random.Random,
          start: Callable = forked) -> tuple[bool, str]:
    """One trial: 1 or 2 kills, each a uniform random time into the run (0 to `train_s`, the uninterrupted
    run's training time), then the run to its end; (equal to `reference`, what happened). A run that ends
    before its first kill starts again from scratch, so every trial kills at least once."""
    notes, kills = [], rng.randint(1, 2)
    while kills:
        delay = rng.uniform(0.0, train_s)
        if kill_when(start(preset, out), into_the_run(out, delay)):
            notes.append(f"killed {delay:.1f} s in, {stage(out)}")
            kills -= 1
        elif len(notes) == 0 or notes[-1].startswith("ended"):
            notes.append(f"ended before {delay:.1f} s in: again from scratch")
            shutil.rmtree(out)
        else:
            break  # the resumed run finished before a second kill
    finish(preset, out, start)
    diffs = differences(reference, out)
    return not diffs, "; ".join(notes) + (f" -> DIFFER: {', '.join(diffs[:6])}" if diffs else " -> equal")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", choices=sorted(ARGS), required=True)
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0, help="seed of the kill moments")
    parser.add_argument("--out", type=Path, required=True, help="scratch folder (run folders and logs)")
    parser.add_argument("--exec", action="store_true",
                        help="start each run as `python -m nbv.cli train` (seconds of imports each), "
                             "not as a forkserver child")
    args = parser.parse_args(argv)
    start = launch if args.exec else forked
    if not args.exec:
        preload_forkserver()
    args.out.mkdir(parents=True, exist_ok=True)
    reference = args.out / f"{args.preset}-reference"
    began = time.perf_counter()
    process = start(args.preset, reference)
    while process.poll() is None and not (reference / "metrics.csv").exists():
        time.sleep(POLL_S)
    opened = time.perf_counter()
    if process.wait() != 0:
        raise SystemExit(f"the uninterrupted run failed: see {reference}.log")
    train_s = time.perf_counter() - opened
    print(f"{args.preset}: uninterrupted run {time.perf_counter() - began:.1f} s, training {train_s:.1f} s",
          flush=True)
    rng, passed, killed = random.Random(args.seed), 0, 0
    for k in range(args.trials):
        ok, note = trial(args.preset, reference, args.out / f"{args.preset}-trial{k}", train_s, rng, start)
        passed += ok
        killed += note.count("killed ")
        print(f"trial {k}: {note}", flush=True)
    print(f"{args.preset}: passed {passed}/{args.trials} ({killed} kills)")
    return 0 if passed == args.trials else 1


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))  # so forkserver children import this file as scripts.kill_resume
    from scripts.kill_resume import main as harness

    sys.exit(harness())
