"""Re-run the reliability probe at d439c96 (issue 28) against this checkout: every failing case F1-F39 of
`shared/reviews/reliability-probe-d439c96.md` with its reproduction, and passing cases rebuilt from the
report's method per part (SIGKILL with the output hashed before and after, two writers, a 3 MiB tmpfs,
training killed and resumed, dataset / policy / mesh mutations, bad values).

Each case runs in its own folder under `--scratch`, niced (`nice -n 10`), at most two at a time, with a
timeout and a cap on its process tree's RSS; its outcome is classed as the report's columns: passed,
traceback, vague (an error that does not name what is wrong), silent (invalid data accepted, or a wrong
result), lost-partial, hang-memory. Settings are the report's: 64x48 at 1 spp, DS8 / DS40.

    PYTHONPATH=. python scripts/reliability_probe.py --scratch /tmp/probe --out paper_results/reliability
    PYTHONPATH=. python scripts/reliability_probe.py --only F3,F24   # some cases only

prints the counts per part and writes OUT/probe.json and OUT/probe.md (per case: part, id, command, outcome,
last printed line) with the commit it ran at.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
import zipfile
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import psutil

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
CAM = "--width 64 --height 48 --spp 1"
TRAIN = (
    "nbv train --preset paper --scene test_building --width 32 --height 24 --spp 1 --obs-size 16 "
    "--history 2 --max-steps 6 --frames 24 --frames-per-batch 4 --init-random-frames 8 "
    "--checkpoint-every 12 --batch-size 4 "
    "--channels 4 --hidden 16 --location-hidden 8 --feature-backend opencv --max-features 50 --no-progress "
    "--threads 1 --workers 1 --members 1 --buffer-size 1000"
)
SCAN = "nbv scan test_building circle --views 4 $CAM"
PLAN2 = "nbv plan test_building --planner circle --views 2 --no-full-scan $CAM --out p"
COMPARE = "nbv compare test_building --planners circle random --seeds 0 --views 2 $CAM --out c"
OUTCOMES = ("passed", "traceback", "vague", "silent", "lost-partial", "hang-memory")
PARTS = {
    1: "SIGKILL at random moments, symlinked --out, stale temp folders",
    2: "two writers on one --out",
    3: "disk full (3 MiB tmpfs)",
    4: "nbv train killed / stopped and resumed",
    5: "dataset-reader mutations",
    6: "policy / checkpoint files",
    7: "mesh inputs",
    8: "bad command-line values and environment",
}
MEMORY_CAP = 5 * 2**30
"""RSS of a case's process tree past which it is killed and classed hang-memory."""


@dataclass
class Result:
    """What a command did: exit status, combined output, and whether it was killed (timeout / memory)."""

    rc: int
    output: str
    killed: str = ""

    @property
    def last(self) -> str:
        """The last printed line (progress-bar returns split, box borders stripped)."""
        lines = [line.strip(" │╭╰─╮╯\t") for line in re.split(r"[\r\n]", self.output)]
        lines = [line for line in lines if line and not line.startswith("For full helptext")]
        return (self.killed + ": " if self.killed else "") + (lines[-1] if lines else "")


@dataclass
class Case:
    """One probe case: `command` (bash, in the case folder) and the outcome expected now."""

    part: int
    id: str
    command: str
    expect: str = "error"
    """error: a named error whose text holds `words`; ok: rc 0 (and `check`); warn: rc 0 with `words` in
    the output, or a named error; either: rc 0 or a named error."""
    words: tuple[str, ...] = ()
    setup: str | Callable[[Path], None] = ""
    check: Callable[[Path, Result], tuple[str, str] | None] | None = None
    teardown: str = ""
    timeout: int = 100
    memory: int = 0
    """RSS cap of the process tree (0: MEMORY_CAP)."""
    fn: Callable[[Path], tuple[str, str]] | None = None
    """A case run in Python (kills, races, training): returns (outcome, last line)."""
    report: dict = field(default_factory=dict)


def environment(scratch: Path) -> dict[str, str]:
    """The environment every case runs in: this checkout's code, `nbv` on PATH, DS8 / DS40 / CAM."""
    return {
        **os.environ,
        "PYTHONPATH": str(ROOT),
        "PATH": f"{BIN}:{os.environ['PATH']}",
        "NBV_CACHE_DIR": str(scratch / "cache"),
        "DS8": str(scratch / "DS8"),
        "DS40": str(scratch / "DS40"),
        "CAM": CAM,
        "POLICY": str(ROOT / "nbv/planning/shipped/policy.pt"),
        "PYTHON": sys.executable,
    }


ENV: dict[str, str] = {}


def tree_rss(pid: int) -> int:
    """RSS of a process and all its descendants, in bytes."""
    try:
        root = psutil.Process(pid)
        procs = [root, *root.children(recursive=True)]
    except psutil.NoSuchProcess:
        return 0
    total = 0
    for proc in procs:
        try:
            total += proc.memory_info().rss
        except psutil.NoSuchProcess:
            pass
    return total


def start(command: str, cwd: Path, log: Path) -> subprocess.Popen:
    """Start `command` under bash, niced, in its own process group, output to `log`."""
    with open(log, "wb") as out:
        return subprocess.Popen(
            ["nice", "-n", "10", "bash", "-c", command],
            cwd=cwd,
            env=ENV,
            stdout=out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )


def kill_group(proc: subprocess.Popen) -> None:
    """SIGKILL a process group started by `start`."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()


def wait(proc: subprocess.Popen, log: Path, timeout: float, memory: int = 0) -> Result:
    """Wait for `proc` at most `timeout` s with its tree under `memory` (MEMORY_CAP); the Result."""
    deadline, killed, memory = time.monotonic() + timeout, "", memory or MEMORY_CAP
    while proc.poll() is None:
        if time.monotonic() > deadline:
            killed = f"timeout {timeout:.0f} s"
        elif tree_rss(proc.pid) > memory:
            killed = f"RSS over {memory / 2**30:.1f} GiB"
        if killed:
            kill_group(proc)
            break
        time.sleep(0.25)
    return Result(proc.returncode, log.read_text(errors="replace"), killed)


def sh(command: str, cwd: Path, timeout: float = 100, name: str = "run", memory: int = 0) -> Result:
    """Run `command` in `cwd` to its end (or the timeout / memory cap)."""
    log = cwd / f".{name}.log"
    return wait(start(command, cwd, log), log, timeout, memory)


def named_in(word: str, text: str) -> bool:
    """Whether `text` names `word` (an option is named as --voxel-size-m or as its field voxel_size_m)."""
    word = word.lstrip("-").lower()
    return word in text or word.replace("-", "_") in text


def classify(case: Case, result: Result) -> str:
    """The report's column for `result` of `case`."""
    if result.killed:
        return "hang-memory"
    if "Traceback (most recent call last)" in result.output or re.match(
        r"^[\w.]*(Error|Exception): ", result.last
    ):
        return "traceback"
    tail = " ".join(result.output.splitlines()[-25:]).lower()
    named = result.rc != 0 and "error" in tail
    if case.expect == "error":
        if result.rc == 0:
            return "silent"
        return "passed" if all(named_in(w, tail) for w in case.words) else "vague"
    if case.expect == "warn":
        if result.rc == 0:
            return "passed" if all(w.lower() in result.output.lower() for w in case.words) else "silent"
        return "passed" if named else "vague"
    if case.expect == "either":
        return "passed" if result.rc == 0 or named else "vague"
    return "passed" if result.rc == 0 else ("vague" if not named else "silent")


def run_case(case: Case, scratch: Path) -> dict:
    """Run one case in a fresh folder; its record for probe.json."""
    folder = scratch / "cases" / case.id
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    began = time.monotonic()
    try:
        if case.fn is not None:
            outcome, last = case.fn(folder)
        else:
            outcome, last = shell_case(case, folder)
    except Exception as err:  # the harness's own failure, reported as such rather than hidden
        outcome, last = "harness-error", f"{type(err).__name__}: {err}"
    record = {
        "part": case.part,
        "id": case.id,
        "command": case.command,
        "outcome": outcome,
        "last_line": last[-400:],
        "seconds": round(time.monotonic() - began, 1),
        **case.report,
    }
    print(
        f"[{record['seconds']:6.1f} s] part {case.part} {case.id:<28} {outcome:<13} {last[-150:]}", flush=True
    )
    return record


def shell_case(case: Case, folder: Path) -> tuple[str, str]:
    """A shell case: setup, command, classification, check, teardown."""
    try:
        if callable(case.setup):
            case.setup(folder)
        elif case.setup:
            done = sh(case.setup, folder, 300, "setup")
            if done.rc != 0:
                return "harness-error", "setup failed: " + done.last
        result = sh(case.command, folder, case.timeout, memory=case.memory)
        outcome = classify(case, result)
        last = result.last
        if case.check is not None and outcome == "passed":
            checked = case.check(folder, result)
            if checked is not None:
                outcome, note = checked
                last = f"{last} [{note}]"
        return outcome, last
    finally:
        if case.teardown:
            sh(case.teardown, folder, 60, "teardown")


# ---------------------------------------------------------------- output hashing (parts 1-3)

VOLATILE = re.compile(r"(time|_s$|seconds|date|elapsed|created|pid|host|overwrite|^out$|path|version|commit)")


def _normal(value):
    if isinstance(value, dict):
        return {k: _normal(v) for k, v in value.items() if not VOLATILE.search(k)}
    if isinstance(value, list):
        return [_normal(v) for v in value]
    return value


def digest(folder: Path) -> dict[str, str]:
    """Each file of `folder`: a symlink by its target, JSON without timings and paths, else its bytes."""
    out = {}
    if not folder.exists():
        return out
    for path in sorted(p for p in folder.rglob("*") if not p.is_dir() or p.is_symlink()):
        rel = str(path.relative_to(folder))
        if path.is_symlink():
            out[rel] = "-> " + os.readlink(path)
        elif path.suffix == ".json":
            try:
                out[rel] = json.dumps(_normal(json.loads(path.read_text())), sort_keys=True)
            except ValueError:
                out[rel] = "bad json " + hashlib.sha256(path.read_bytes()).hexdigest()
        else:
            out[rel] = hashlib.sha256(path.read_bytes()).hexdigest()
    return out


def same_structure(a: dict[str, str], b: dict[str, str]) -> bool:
    """The same files with the same JSON records (binary files may differ by render noise)."""
    return a.keys() == b.keys() and all(
        a[k] == b[k] for k in a if k.endswith(".json") or a[k].startswith("->")
    )


def strays(folder: Path, name: str) -> list[str]:
    """Hidden temp / old folders of output `name` left beside it."""
    return sorted(
        p.name for p in folder.iterdir() if p.name.startswith(f".{name}.") and not p.name.endswith(".log")
    )


# ---------------------------------------------------------------- part 1: SIGKILL at random moments


def kill_case(
    first: str, second: str, out: str, seed: int, post_temp: bool
) -> Callable[[Path], tuple[str, str]]:
    """Write output A with `first`, SIGKILL `second --overwrite` (B) at a random moment (uniform over a
    run, or just after its temp folder appears), hash before and after; rerun B. Passed when the output
    is A whole or B whole, the rerun succeeds and nothing stray is left."""

    def run(folder: Path) -> tuple[str, str]:
        began = time.monotonic()
        done = sh(f"{first} --out {out}", folder, 300, "a")
        if done.rc != 0:
            return "harness-error", "A failed: " + done.last
        length, before = time.monotonic() - began, digest(folder / out)
        rng = random.Random(seed)
        proc = start(f"{second} --out {out} --overwrite", folder, folder / ".b.log")
        t0, moment = time.monotonic(), rng.uniform(0.3, max(0.5, length))
        while proc.poll() is None and time.monotonic() - t0 < 300:
            if (not post_temp and time.monotonic() - t0 >= moment) or (post_temp and strays(folder, out)):
                break
            time.sleep(0.02)
        finished = proc.poll() is not None
        kill_group(proc)
        after = digest(folder / out)
        rerun = sh(f"{second} --out {out} --overwrite", folder, 300, "rerun")
        if rerun.rc != 0 or rerun.killed:
            return classify(Case(0, "", ""), rerun), "rerun failed: " + rerun.last
        new, left = digest(folder / out), strays(folder, out)
        when = f"{'finished before the kill' if finished else f'killed at {time.monotonic() - t0:.1f} s'}"
        if after == before:
            state = "old output intact"
        elif same_structure(after, new):
            state = "new output complete"
        else:
            return "lost-partial", f"{when}: output neither A nor B ({sorted(set(after) ^ set(new))[:4]})"
        if left:
            return "lost-partial", f"{when}, {state}; stray after the rerun: {left}"
        return "passed", f"{when}: {state}; rerun rc 0, nothing stray"

    return run


KILLS = {
    "scan": (
        "nbv scan test_building circle --views 8 $CAM",
        "nbv scan test_building circle --views 16 --seed 3 $CAM",
    ),
    "refine": ("nbv refine $DS8 --threads 1", "nbv refine $DS8 --threads 1 --words 64"),
    "reconstruct": ("nbv reconstruct $DS8 --voxel-size-m 0.01", "nbv reconstruct $DS8 --voxel-size-m 0.012"),
    "plan": (
        "nbv plan test_building --planner circle --views 3 --no-full-scan $CAM",
        "nbv plan test_building --planner circle --views 4 --no-full-scan $CAM",
    ),
    "export": (
        "nbv export $DS40 --format colmap --images copy",
        "nbv export $DS40 --format colmap --images copy --points",
    ),
}


def symlinked_out(folder: Path) -> tuple[str, str]:
    """F1: `--out` a symlink to a folder holding A; --overwrite must resolve or refuse it."""
    sh("cp -r $DS8 real && ln -s real link", folder)
    done = sh("nbv scan test_building circle --views 4 $CAM --out link --overwrite", folder, 200)
    outcome = classify(Case(0, "", "", expect="either"), done)
    if outcome != "passed" or done.rc != 0:
        return outcome, done.last
    link, frames = folder / "link", len(json.loads((folder / "real/transforms.json").read_text())["frames"])
    left = [p.name for p in folder.iterdir() if p.name.startswith(".link.") and not p.name.endswith(".log")]
    if not link.is_symlink() or frames != 4 or left:
        return (
            "silent",
            f"rc 0; link is a symlink: {link.is_symlink()}, real has {frames} frames, stray {left}",
        )
    return "passed", f"rc 0; link still a symlink, its target holds the new 4-frame scan [{done.last}]"


def zombie_stray(folder: Path) -> tuple[str, str]:
    """F2: SIGKILL a scan run under nice/timeout about 1 s in, rerun at once: no temp folder left."""
    proc = start(
        "timeout 100 nbv scan test_building circle --views 40 $CAM --out d --overwrite",
        folder,
        folder / ".k.log",
    )
    t0 = time.monotonic()
    while not strays(folder, "d") and time.monotonic() - t0 < 120 and proc.poll() is None:
        time.sleep(0.05)
    time.sleep(1.0)
    kill_group(proc)
    rerun = sh("nbv scan test_building circle --views 8 $CAM --out d --overwrite", folder, 200)
    left = strays(folder, "d")
    if rerun.rc != 0:
        return classify(Case(0, "", "", expect="ok"), rerun), rerun.last
    return ("lost-partial", f"stray {left} after the rerun") if left else ("passed", "rerun rc 0, no stray")


def part1() -> list[Case]:
    """Part 1: F1, F2 and SIGKILLs of scan, refine, reconstruct, plan and export at random moments."""
    cases = [
        Case(
            1,
            "F1",
            "cp -r DS8 real; ln -s real link; nbv scan test_building circle --views 4 $CAM "
            "--out link --overwrite",
            fn=symlinked_out,
        ),
        Case(
            1,
            "F2",
            "timeout 100 nbv scan ... --views 40 --out d --overwrite & kill -9 its group ~1 s "
            "after its temp folder appears; rerun at once; ls -a",
            fn=zombie_stray,
        ),
    ]
    for name, (first, second) in KILLS.items():
        for trial in range(3):
            post = trial == 2
            cases.append(
                Case(
                    1,
                    f"kill-{name}-{trial}",
                    f"{first} --out X; {second} --out X --overwrite, "
                    f"SIGKILL {'after its temp folder appears' if post else f'at random (seed {trial})'}; "
                    f"rerun; hash X before/after",
                    fn=kill_case(first, second, "X", trial, post),
                )
            )
    return cases


# ---------------------------------------------------------------- part 2: two writers


def together(folder: Path, first: str, second: str, stagger: float = 0.0) -> tuple[Result, Result]:
    """Run two commands in `folder`, the second `stagger` s after the first; both Results."""
    a = start(first, folder, folder / ".w1.log")
    time.sleep(stagger)
    b = start(second, folder, folder / ".w2.log")
    return wait(a, folder / ".w1.log", 300), wait(b, folder / ".w2.log", 300)


def frames_of(root: Path) -> int | None:
    """How many frames the dataset at `root` has (None: not a readable dataset)."""
    from render.dataset import read_dataset

    try:
        return len(read_dataset(root).frames)
    except Exception:
        return None


def two_scans(overwrite: bool, stagger: float) -> Callable[[Path], tuple[str, str]]:
    """F3 and its passing kin: two scans on one fresh `--out`; exactly one complete dataset, the other run
    a named error (or, with --overwrite, both succeed and the folder is one of the two whole)."""
    flag = " --overwrite" if overwrite else ""

    def run(folder: Path) -> tuple[str, str]:
        a, b = together(
            folder,
            f"nbv scan test_building circle --views 12 --seed 5 $CAM --out same{flag}",
            f"nbv scan test_building circle --views 10 --seed 7 $CAM --out same{flag}",
            stagger,
        )
        for r in (a, b):
            if r.killed or "Traceback" in r.output:
                return classify(Case(0, "", ""), r), r.last
        frames, left = frames_of(folder / "same"), strays(folder, "same")
        won = [r.rc == 0 for r in (a, b)]
        note = f"rc {a.rc}/{b.rc}, dataset of {frames} frames, stray {left}; {(a if a.rc else b).last}"
        if frames not in (12, 10) or left:
            return "lost-partial", note
        if all(won) and not overwrite:
            return "lost-partial", "both succeeded without --overwrite: one dataset lost; " + note
        if not any(won):
            return "lost-partial", "both failed; " + note
        if won.count(True) == 1 and frames != (12 if won[0] else 10):
            return "lost-partial", "the winner's dataset is not what is there; " + note
        loser = b if b.rc else a
        if won.count(True) == 1 and "error" not in loser.last.lower():
            return "vague", note
        return "passed", note

    return run


def reconstruct_vs_evaluate(folder: Path) -> tuple[str, str]:
    """F4: `reconstruct --overwrite` racing `evaluate` on one folder: R/mesh.ply must be the 0.008 m mesh
    (or one of the runs refused with a named error)."""
    sh("nbv reconstruct $DS40 --voxel-size-m 0.008 --out R8", folder, 300)
    sh("nbv reconstruct $DS40 --voxel-size-m 0.01 --out R", folder, 300)
    a, b = together(
        folder,
        "nbv evaluate R/mesh.ply --gt test_building --metric-points 20000 --out R",
        "nbv reconstruct $DS40 --voxel-size-m 0.008 --out R --overwrite",
        0.2,
    )
    for r in (a, b):
        if r.killed or "Traceback" in r.output:
            return classify(Case(0, "", ""), r), r.last
    mesh = hashlib.sha256((folder / "R/mesh.ply").read_bytes()).hexdigest()
    new = mesh == hashlib.sha256((folder / "R8/mesh.ply").read_bytes()).hexdigest()
    note = f"evaluate rc {a.rc}, reconstruct rc {b.rc}, mesh.ply is the {'0.008' if new else 'OLD 0.01'} mesh"
    if b.rc == 0 and not new:
        return "lost-partial", note
    if b.rc != 0 and "error" not in b.last.lower():
        return "vague", note + "; " + b.last
    return "passed", note + ("" if b.rc == 0 else "; " + b.last)


def two_reconstructs(folder: Path) -> tuple[str, str]:
    """Two `reconstruct --overwrite` together: one complete trio, the other run a named error if any."""
    a, b = together(
        folder,
        "nbv reconstruct $DS8 --voxel-size-m 0.01 --out R --overwrite",
        "nbv reconstruct $DS8 --voxel-size-m 0.012 --out R --overwrite",
        0.1,
    )
    files = sorted(p.name for p in (folder / "R").iterdir()) if (folder / "R").exists() else []
    note = f"rc {a.rc}/{b.rc}, R holds {files}, stray {strays(folder, 'R')}"
    bad = [r for r in (a, b) if r.rc != 0 and "error" not in r.last.lower()]
    if "mesh.ply" not in files or strays(folder, "R") or not (a.rc == 0 or b.rc == 0):
        return "lost-partial", note
    return ("vague", note + "; " + bad[0].last) if bad else ("passed", note)


def both_refuse(folder: Path) -> tuple[str, str]:
    """The output already present, no --overwrite: both runs refuse cleanly, the output untouched."""
    sh("cp -r $DS8 same", folder)
    before = digest(folder / "same")
    a, b = together(
        folder,
        "nbv scan test_building circle --views 4 $CAM --out same",
        "nbv scan test_building circle --views 5 $CAM --out same",
        0.0,
    )
    note = f"rc {a.rc}/{b.rc}; {b.last}"
    if digest(folder / "same") != before:
        return "lost-partial", note
    if a.rc == 0 or b.rc == 0:
        return "silent", note
    return ("passed" if all("exists" in r.last or "error" in r.last for r in (a, b)) else "vague"), note


def part2() -> list[Case]:
    """Part 2: F3, F4 and the passing two-writer cases."""
    scans = (
        "nbv scan test_building circle --views 12 --seed 5 $CAM --out same{o} & "
        "nbv scan test_building circle --views 10 --seed 7 $CAM --out same{o}; wait"
    )
    cases = [Case(2, f"F3-{i}", scans.format(o=""), fn=two_scans(False, 0.0)) for i in range(3)]
    cases += [
        Case(2, f"F3-stagger{s}", scans.format(o="") + f" (stagger {s} s)", fn=two_scans(False, s))
        for s in (0.3, 1.0)
    ]
    cases += [
        Case(
            2,
            f"F4-{i}",
            "nbv reconstruct DS40 --voxel-size-m 0.01 --out R; nbv evaluate R/mesh.ply --gt "
            "test_building --metric-points 20000 --out R & sleep 0.2; nbv reconstruct DS40 --voxel-size-m "
            "0.008 --out R --overwrite; wait",
            fn=reconstruct_vs_evaluate,
        )
        for i in range(2)
    ]
    cases += [
        Case(
            2,
            f"overwrite-scans-{s}",
            scans.format(o=" --overwrite") + f" (stagger {s} s)",
            fn=two_scans(True, s),
        )
        for s in (0.0, 0.5)
    ]
    cases.append(
        Case(
            2, "two-reconstructs", "two nbv reconstruct DS8 --overwrite --out R at once", fn=two_reconstructs
        )
    )
    cases.append(
        Case(
            2,
            "present-no-overwrite",
            "two scans onto an existing dataset without --overwrite",
            fn=both_refuse,
        )
    )
    return cases


# ---------------------------------------------------------------- part 3: disk full


def tmpfs(free_kb: int, extra: str = "") -> str:
    """Setup: a 3 MiB tmpfs at `small` (needs root), filled to `free_kb` KiB free, then `extra`."""
    fill = f"head -c $(( $(stat -f -c '%a*%S' small) - {free_kb}*1024 )) /dev/zero > small/fill || true"
    return (
        f"mkdir -p small && mount -t tmpfs -o size=3M tmpfs small && {extra + ' && ' if extra else ''}{fill}"
    )


def left_on_disk(
    keep: tuple[str, ...] = ("fill",), old: str = ""
) -> Callable[[Path, Result], tuple[str, str]]:
    """Check: nothing but `keep` on the tmpfs, and `old` (a copy of DS8) byte-identical."""

    def check(folder: Path, result: Result) -> tuple[str, str] | None:
        names = sorted(p.name for p in (folder / "small").iterdir())
        extra = [n for n in names if n not in keep]
        if extra:
            return "lost-partial", f"left on the full disk: {extra}"
        if old and digest(folder / "small" / old) != digest(Path(ENV["DS8"])):
            return "lost-partial", f"the old output {old} changed"
        return None

    return check


# Part 3: F5 and F6 (every command on a full disk) as the report's 15 runs.
down, nospace = "umount -l small", ("no space left", "small")
big = "nbv scan test_building circle --views 40 --width 320 --height 240 --spp 1"
cases = [
    Case(
        3,
        "F5-scan",
        f"{big} --out small/s1",
        words=nospace,
        setup=tmpfs(3072),
        check=left_on_disk(),
        teardown=down,
        timeout=200,
    )
]
for free in (40, 120, 300):
    cases.append(
        Case(
            3,
            f"F5-scan-free{free}k",
            "nbv scan test_building circle --views 40 $CAM --out small/s1",
            words=nospace,
            setup=tmpfs(free),
            check=left_on_disk(),
            teardown=down,
            timeout=200,
        )
    )
cases += [
    Case(
        3,
        "F5-scan-overwrite",
        f"{big} --out small/old --overwrite",
        words=nospace,
        setup=tmpfs(1200, "cp -r $DS8 small/old"),
        check=left_on_disk(("fill", "old"), "old"),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F5-reconstruct",
        "nbv reconstruct $DS40 --voxel-size-m 0.005 --out small/r",
        words=nospace,
        setup=tmpfs(8),
        check=left_on_disk(),
        teardown=down,
    ),
    Case(
        3,
        "F5-reconstruct-overwrite",
        "nbv reconstruct $DS40 --voxel-size-m 0.005 --out small/old --overwrite",
        words=nospace,
        setup=tmpfs(8, "cp -r $DS8 small/old"),
        check=left_on_disk(("fill", "old"), "old"),
        teardown=down,
    ),
    Case(
        3,
        "F5-export-copy",
        "nbv export $DS40 --format colmap --images copy --out small/e1",
        words=nospace,
        setup=tmpfs(60),
        check=left_on_disk(),
        teardown=down,
    ),
    Case(
        3,
        "F5-export-overwrite",
        "nbv export $DS40 --format colmap --images copy --out small/old --overwrite",
        words=nospace,
        setup=tmpfs(60, "cp -r $DS8 small/old"),
        check=left_on_disk(("fill", "old"), "old"),
        teardown=down,
    ),
    Case(
        3,
        "F5-refine",
        "nbv refine $DS40 --threads 1 --out small/f",
        words=nospace,
        setup=tmpfs(4),
        check=left_on_disk(),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F5-plan",
        "nbv plan test_building --planner circle --views 3 --no-full-scan $CAM --out small/p",
        words=nospace,
        setup=tmpfs(4),
        check=left_on_disk(),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F6-refine-cache",
        "nbv refine $DS40 --threads 1 --cache-dir small/cache --out o",
        expect="warn",
        words=("cache",),
        setup=tmpfs(8),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F6-scan-cache",
        "NBV_CACHE_DIR=$PWD/small/cache nbv scan test_building circle --views 4 $CAM --out s",
        expect="warn",
        words=("cache",),
        setup=tmpfs(8),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F6-plan-cache",
        "NBV_CACHE_DIR=$PWD/small/cache nbv plan test_building --planner circle --views 3 "
        "--no-full-scan $CAM --out p",
        expect="warn",
        words=("cache",),
        setup=tmpfs(8),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F5-train",
        TRAIN + " --out small/t",
        words=nospace,
        setup=tmpfs(16),
        teardown=down,
        timeout=200,
    ),
]
PART3 = cases


def part3() -> list[Case]:
    """Part 3: F5 and F6 (every command on a full disk) as the report's 15 runs."""
    return list(PART3)


# ---------------------------------------------------------------- part 4: training killed and resumed

_REFERENCES: dict[str, tuple[Path, float]] = {}
_REFERENCE_LOCK = threading.Lock()


def reference(preset: str, scratch: Path) -> tuple[Path, float]:
    """The uninterrupted run of `preset` (scripts/kill_resume.py's tiny settings) and its training time."""
    from scripts import kill_resume as kr

    with _REFERENCE_LOCK:
        if preset not in _REFERENCES:
            out = scratch / f"train-{preset}-reference"
            shutil.rmtree(out, ignore_errors=True)
            proc = kr.launch(preset, out)
            while proc.poll() is None and not (out / "metrics.csv").exists():
                time.sleep(0.01)
            opened = time.monotonic()
            if proc.wait() != 0:
                raise RuntimeError(f"the uninterrupted {preset} run failed: see {out}.log")
            _REFERENCES[preset] = (out, time.monotonic() - opened)
        return _REFERENCES[preset]


def _train_outcome(ref: Path, out: Path, notes: str, ignore: tuple[str, ...] = ()) -> tuple[str, str]:
    from scripts import kill_resume as kr

    log = out.with_name(out.name + ".log").read_text(errors="replace")
    if "Traceback" in log:
        return "traceback", Result(1, log).last
    diffs = [d for d in kr.differences(ref, out) if d not in ignore]
    if not diffs:
        return "passed", notes + " -> equal to the uninterrupted run"
    kind = "lost-partial" if diffs == ["metrics.csv"] or diffs == ["validation.csv"] else "silent"
    return kind, f"{notes} -> DIFFER: {', '.join(diffs[:5])}"


def stop_and_continue(preset: str, scratch: Path) -> Callable[[Path], tuple[str, str]]:
    """F7 (default preset: lattice + coverage reward) and F8 (paper): a clean stop at 24 frames (a checkpoint
    and validation moment of the 40-frame run, so both validate at the same frames), then the same run to 40
    frames, against one 40-frame run. policy.pt records the --frames of the run that wrote it (24), so that
    one config field is left out of the comparison."""

    def run(folder: Path) -> tuple[str, str]:
        from scripts import kill_resume as kr

        ref, _ = reference(preset, scratch)
        args = list(kr.ARGS[preset])
        args[args.index("--frames") + 1] = "24"
        kr.ARGS[f"{preset}-24"] = args
        out = folder / "run"
        for name in (f"{preset}-24", preset):
            if kr.launch(name, out).wait() != 0:
                return _train_outcome(ref, out, f"{name} run failed")
        ignore = ("policy.pt.config.collector.frames",)
        return _train_outcome(ref, out, "stopped at 24 frames, continued to 40", ignore)

    return run


def kill_at(preset: str, scratch: Path, moment: str, seed: int = 0) -> Callable[[Path], tuple[str, str]]:
    """F9 (`before`: SIGKILL before the first checkpoint, metrics.csv still empty), F10 (`flush`: at the
    second log flush) and F11 (`random`: 1-2 kills at random moments, scripts/kill_resume.trial)."""

    def run(folder: Path) -> tuple[str, str]:
        from scripts import kill_resume as kr

        ref, train_s = reference(preset, scratch)
        out = folder / "run"
        if moment == "random":
            ok, note = kr.trial(preset, ref, out, train_s, random.Random(seed), kr.launch)
            return _train_outcome(ref, out, note.split(" -> ")[0])
        when = kr.before_first_checkpoint(out) if moment == "before" else kr.at_second_log_flush(out)
        killed = kr.kill_when(kr.launch(preset, out), when, 300)
        stage = kr.stage(out) if killed else "ended before the kill"
        if kr.launch(preset, out).wait() != 0:
            return _train_outcome(ref, out, f"killed {stage}; the rerun failed")
        return _train_outcome(ref, out, f"killed {stage}, rerun")

    return run


def part4(scratch: Path) -> list[Case]:
    """Part 4: F7-F11 with scripts/kill_resume.py's tiny settings (40 frames, checkpoints every 12)."""
    train = "nbv train <kill_resume.ARGS[{p}]> --out R"
    cases = [
        Case(
            4,
            "F7-default-stop-continue",
            f"{train.format(p='default')} --frames 24; then --frames 40; compare with one 40-frame run",
            fn=stop_and_continue("default", scratch),
            timeout=600,
        ),
        Case(
            4,
            "F8-paper-stop-continue",
            f"{train.format(p='paper')} --frames 24; then --frames 40; compare with one 40-frame run",
            fn=stop_and_continue("paper", scratch),
            timeout=600,
        ),
    ]
    for preset in ("paper", "default"):
        cases += [
            Case(
                4,
                f"F9-{preset}-kill-before-checkpoint",
                f"{train.format(p=preset)}, SIGKILL while metrics.csv is 0 bytes, rerun, compare",
                fn=kill_at(preset, scratch, "before"),
            ),
            Case(
                4,
                f"F10-{preset}-kill-at-second-flush",
                f"{train.format(p=preset)}, SIGKILL when "
                "metrics.csv grows after the 1st checkpoint, rerun, compare",
                fn=kill_at(preset, scratch, "flush"),
            ),
        ]
    cases += [
        Case(
            4,
            f"F11-{p}-random-kills-{s}",
            f"{train.format(p=p)}, 1-2 SIGKILLs at random (seed {s}), rerun, compare every tensor and log",
            fn=kill_at(p, scratch, "random", s),
        )
        for p, s in (("paper", 1), ("paper", 2), ("paper", 3), ("default", 4))
    ]
    return cases


# ---------------------------------------------------------------- part 5: dataset reader


def mutated(change: Callable[[Path], None]) -> Callable[[Path], None]:
    """Setup: a copy of DS8 at `d`, then `change(d)`."""

    def setup(folder: Path) -> None:
        shutil.copytree(ENV["DS8"], folder / "d", symlinks=True)
        change(folder / "d")

    return setup


def text(old: str, new: str) -> Callable[[Path], None]:
    """Replace the first `old` in d/transforms.json by `new`."""

    def change(root: Path) -> None:
        path = root / "transforms.json"
        body = path.read_text()
        assert old in body, old
        path.write_text(body.replace(old, new, 1))

    return change


def doc(edit: Callable[[dict], None]) -> Callable[[Path], None]:
    """Edit d/transforms.json as a dict."""

    def change(root: Path) -> None:
        path = root / "transforms.json"
        record = json.loads(path.read_text())
        edit(record)
        path.write_text(json.dumps(record, indent=1))

    return change


def short_idat(root: Path) -> None:
    """F14: images/0000.png's IDAT holding only its first 24 of 48 rows (a valid stream, valid CRCs)."""
    import struct
    import zlib

    path, data, chunks, pos = root / "images/0000.png", (root / "images/0000.png").read_bytes(), [], 8
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        chunks.append((kind, data[pos + 8 : pos + 8 + length]))
        pos += 12 + length
    raw = zlib.decompress(b"".join(body for kind, body in chunks if kind == b"IDAT"))
    chunks = [c for c in chunks if c[0] not in (b"IDAT", b"IEND")]
    chunks += [(b"IDAT", zlib.compress(raw[: (64 * 3 + 1) * 24])), (b"IEND", b"")]
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + b"".join(
            struct.pack(">I", len(b)) + k + b + struct.pack(">I", zlib.crc32(k + b)) for k, b in chunks
        )
    )


def apng(root: Path) -> None:
    """F16: an APNG whose default image is not part of the animation."""
    from PIL import Image

    path = root / "images/0000.png"
    still = Image.open(path).convert("RGB")
    still.save(path, save_all=True, append_images=[Image.new("RGB", still.size)], default_image=True)


def newline_name(root: Path) -> None:
    """F18: an image file name holding a newline."""
    os.rename(root / "images/0002.png", root / "images/00\n02.png")
    doc(lambda d: d["frames"][2].update(file_path="images/00\n02.png"))(root)


def many_frames(root: Path) -> None:
    """F19: 10^5 frames that all reference one image and depth."""
    doc(lambda d: d.update(frames=[d["frames"][0]] * 100_000))(root)


def interlaced(root: Path) -> None:
    """An Adam7-interlaced image (accepted harmlessly)."""
    from PIL import Image

    image = Image.open(root / "images/0001.png")
    image.save(root / "images/0001.png", interlace=1)


def fuzzed(seed: int) -> Callable[[Path], None]:
    """A mutation by the dataset fuzzer of tests/render/test_dataset_fuzz.py (JSON, text or PNG)."""

    def change(root: Path) -> None:
        from PIL import Image

        from tests.render import test_dataset_fuzz as fz

        rng = np.random.default_rng(seed)
        outside = root.parent / "outside.png"
        Image.fromarray(np.zeros((48, 64, 3), np.uint8)).save(outside)
        if seed % 4 == 3:
            fz._mutate_png(root, rng)
        elif seed % 8 == 2:
            fz._mutate_text(root, rng)
        else:
            fz._edit(
                root, lambda d: [fz._mutate_json(d, rng, outside) for _ in range(int(rng.integers(1, 3)))]
            )

    return change


def _reflect(d: dict) -> None:
    for row in d["frames"][0]["transform_matrix"][:3]:
        row[0] = -row[0]


# Part 5: F12-F19 and passing mutations of DS8 through reconstruct, refine and export.
rec, ref, exp = "nbv reconstruct d --out o", "nbv refine d --threads 1 --out o", "nbv export d --out e"
tj, frames = ("transforms.json",), ("transforms.json", "frames")
cases = [
    Case(
        5,
        "F12-dup-w",
        rec,
        words=("transforms.json", "twice"),
        setup=mutated(text('"w": 64', '"w": 32, "w": 64')),
    ),
    Case(
        5,
        "F12-dup-frames",
        rec,
        words=("transforms.json", "twice"),
        setup=mutated(text('"frames": [', '"frames": [], "frames": [')),
    ),
    Case(
        5,
        "F12-dup-fl_x-refine",
        ref,
        words=("transforms.json", "twice"),
        setup=mutated(text('"fl_x": ', '"fl_x": 1000.0, "fl_x": ')),
    ),
    Case(
        5,
        "F13-aabb-NaN",
        rec,
        words=("transforms.json", "nan"),
        setup=mutated(text('"w": 64', '"aabb_scale": NaN, "w": 64')),
    ),
    Case(
        5,
        "F13-extra-neg-infinity-refine",
        ref,
        words=("transforms.json", "infinity"),
        setup=mutated(
            text('"file_path": "images/0000.png"', '"extra": -Infinity, "file_path": "images/0000.png"')
        ),
    ),
    Case(5, "F14-short-idat", rec, words=("0000.png", "truncated"), setup=mutated(short_idat)),
    Case(5, "F14-short-idat-refine", ref, words=("0000.png", "truncated"), setup=mutated(short_idat)),
    Case(
        5,
        "F15-shared-image",
        rec,
        words=("same file", "pose"),
        setup=mutated(
            doc(
                lambda d: d["frames"][1].update(
                    file_path=d["frames"][0]["file_path"],
                    depth_file_path=d["frames"][0]["depth_file_path"],
                )
            )
        ),
    ),
    Case(5, "F16-apng", rec, words=("0000.png", "apng"), setup=mutated(apng)),
    Case(
        5,
        "F17-lone-surrogate",
        ref,
        words=("file_path", "surrogate"),
        setup=mutated(text('"images/0001.png"', '"images/0001\\ud800.png"')),
    ),
    Case(5, "F18-newline-name-export", exp, words=("file_path",), setup=mutated(newline_name)),
    Case(5, "F19-1e5-frames-refine", ref, expect="either", setup=mutated(many_frames), timeout=150),
    Case(
        5,
        "empty-frame-objects",
        rec,
        words=frames,
        setup=mutated(doc(lambda d: d.update(frames=[{}, {}]))),
    ),
    Case(
        5,
        "proc-environ-symlink",
        rec,
        words=tj,
        setup=mutated(
            lambda r: (
                (r / "transforms.json").unlink(),
                (r / "transforms.json").symlink_to("/proc/self/environ"),
            )
        ),
    ),
    Case(
        5,
        "bare-NaN-fl_x",
        rec,
        words=("fl_x",),
        setup=mutated(text('"fl_x": 62.22222222222222', '"fl_x": NaN')),
    ),
    Case(5, "k1-string", rec, words=("k1",), setup=mutated(doc(lambda d: d.update(k1="0")))),
    Case(5, "k3-tiny", rec, expect="either", setup=mutated(doc(lambda d: d.update(k3=1e-300)))),
    Case(
        5,
        "camera-model-lower",
        rec,
        words=("camera_model",),
        setup=mutated(doc(lambda d: d.update(camera_model="opencv"))),
    ),
    Case(5, "5000-digit-int", rec, words=tj, setup=mutated(text('"w": 64', '"w": ' + "9" * 5000))),
    Case(5, "reflection", rec, words=("rotation",), setup=mutated(doc(_reflect))),
    Case(
        5,
        "folder-as-file-path",
        rec,
        words=("0000.png",),
        setup=mutated(lambda r: ((r / "images/0000.png").unlink(), (r / "images/0000.png").mkdir())),
    ),
    Case(
        5,
        "symlink-png-outside",
        rec,
        words=("0000.png",),
        setup=mutated(
            lambda r: (
                shutil.copy(r / "images/0000.png", r.parent / "out.png"),
                (r / "images/0000.png").unlink(),
                (r / "images/0000.png").symlink_to(r.parent / "out.png"),
            )
        ),
    ),
    Case(
        5,
        "duplicate-identical-frames",
        rec,
        expect="either",
        setup=mutated(doc(lambda d: d["frames"].append(dict(d["frames"][0])))),
    ),
    Case(
        5,
        "source-index-2^70",
        rec,
        expect="either",
        setup=mutated(doc(lambda d: d["frames"][0].setdefault("nbv", {}).update(source_index=2**70))),
    ),
    Case(5, "interlaced-png", rec, expect="ok", setup=mutated(interlaced)),
    Case(
        5,
        "unicode-space-name",
        rec,
        expect="ok",
        setup=mutated(
            lambda r: (
                os.rename(r / "images/0003.png", r / "images/vue 3 é.png"),
                doc(lambda d: d["frames"][3].update(file_path="images/vue 3 é.png"))(r),
            )
        ),
    ),
]
cases += [
    Case(5, f"fuzz-{seed}", rec, expect="either", setup=mutated(fuzzed(seed))) for seed in range(12)
]
PART5 = cases


def part5() -> list[Case]:
    """Part 5: F12-F19 and passing mutations of DS8 through reconstruct, refine and export."""
    return list(PART5)


# ---------------------------------------------------------------- part 6: policy files

PLAN = "nbv plan test_building --planner policy:{f} --views 3 --no-full-scan $CAM --out o"


def policy(name: str, edit: Callable[[dict], None], checksum: bool = True) -> Callable[[Path], None]:
    """Setup: the shipped policy loaded, edited, saved as `name` (its tensor checksum recomputed when
    `checksum`, so the edit itself is what the loader meets)."""

    def setup(folder: Path) -> None:
        import torch

        from nbv.rl.archive import tensor_checksum

        state = torch.load(ENV["POLICY"], map_location="cpu", weights_only=True)
        edit(state)
        if checksum:
            state["checksum"] = tensor_checksum({k: v for k, v in state.items() if k != "checksum"})
        torch.save(state, folder / name)

    return setup


def config_edit(path: str, value) -> Callable[[dict], None]:
    """Set the policy's recorded config at dotted `path` to `value`."""

    def edit(state: dict) -> None:
        record = json.loads(state["config"])
        node, keys = record, path.split(".")
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] = value
        state["config"] = json.dumps(record)

    return edit


def zeroed(folder: Path) -> None:
    """F20: 64 zeroed bytes in the middle of the shipped policy."""
    data = bytearray(Path(ENV["POLICY"]).read_bytes())
    middle = len(data) // 2
    data[middle : middle + 64] = bytes(64)
    (folder / "bad.pt").write_bytes(data)


def zip_bomb(folder: Path) -> None:
    """F23: a ~2 MB zip whose archive/data.pkl inflates to 2 GiB, named .pt."""
    with zipfile.ZipFile(folder / "bomb.pt", "w", zipfile.ZIP_DEFLATED, compresslevel=9) as archive:
        with archive.open("archive/data.pkl", "w", force_zip64=True) as entry:
            block = bytes(2**24)
            for _ in range(128):
                entry.write(block)
        archive.writestr("archive/version", "3\n")


def pickle_bomb(folder: Path) -> None:
    """A code-running pickle in a torch zip (must not run: no PWNED file)."""
    import torch

    class Evil:
        def __reduce__(self):
            return (os.system, (f"touch {folder}/PWNED",))

    torch.save({"format": "nbv-sac-policy", "evil": Evil()}, folder / "evil.pt")


def no_pwned(folder: Path, result: Result) -> tuple[str, str] | None:
    """Check: the pickle's code did not run."""
    return ("silent", "PWNED exists: the pickle ran") if (folder / "PWNED").exists() else None


def _nan_actor(state: dict) -> None:
    for tensor in state["actor"].values():
        if tensor.is_floating_point():
            tensor.fill_(float("nan"))


# Part 6: F20-F23 and the passing policy-file cases for `nbv plan --planner policy:FILE`.
trunc = "head -c $(( $(stat -c %s $POLICY) / 2 )) $POLICY > half.pt"
PART6 = [
    Case(6, "F20-zeroed-bytes", PLAN.format(f="bad.pt"), words=("bad.pt",), setup=zeroed, timeout=150),
    Case(
        6,
        "F21-action-mode-teleport",
        PLAN.format(f="tp.pt"),
        words=("tp.pt", "action_mode"),
        setup=policy("tp.pt", config_edit("env.action_mode", "teleport")),
        timeout=150,
    ),
    Case(
        6,
        "F22-nan-weights",
        PLAN.format(f="nan.pt"),
        words=("nan.pt",),
        setup=policy("nan.pt", _nan_actor),
        timeout=150,
    ),
    Case(
        6,
        "F23-zip-bomb",
        PLAN.format(f="bomb.pt"),
        words=("bomb.pt",),
        setup=zip_bomb,
        memory=2**30,
        timeout=150,
    ),
    Case(6, "truncated-half", PLAN.format(f="half.pt"), words=("half.pt",), setup=trunc, timeout=150),
    Case(6, "empty-file", PLAN.format(f="empty.pt"), words=("empty.pt",), setup="touch empty.pt"),
    Case(6, "directory", PLAN.format(f="dir.pt"), words=("dir.pt",), setup="mkdir dir.pt"),
    Case(6, "fifo", PLAN.format(f="fifo.pt"), words=("fifo.pt",), setup="mkfifo fifo.pt", timeout=60),
    Case(6, "dev-null", PLAN.format(f="/dev/null"), words=("/dev/null",)),
    Case(6, "dev-zero", PLAN.format(f="/dev/zero"), words=("/dev/zero",), timeout=60, memory=2**30),
    Case(
        6,
        "code-running-pickle",
        PLAN.format(f="evil.pt"),
        words=("evil.pt",),
        setup=pickle_bomb,
        check=no_pwned,
    ),
    Case(
        6,
        "config-channels-64",
        PLAN.format(f="c.pt"),
        words=("c.pt",),
        setup=policy("c.pt", config_edit("network.channels", 64)),
    ),
    Case(
        6,
        "version-2",
        PLAN.format(f="v.pt"),
        words=("v.pt",),
        setup=policy("v.pt", lambda s: s.update(version=2)),
    ),
    Case(
        6,
        "foreign-state-dict",
        PLAN.format(f="f.pt"),
        words=("f.pt",),
        setup=policy("f.pt", lambda s: [s.pop(k) for k in list(s) if k != "actor"], checksum=False),
    ),
    Case(
        6,
        "no-checksum-warns",
        PLAN.format(f="nc.pt"),
        expect="warn",
        words=("checksum",),
        setup=policy("nc.pt", lambda s: s.pop("checksum"), checksum=False),
        timeout=150,
    ),
    Case(6, "shipped-policy", PLAN.format(f="$POLICY"), expect="ok", timeout=150),
]


def part6() -> list[Case]:
    """Part 6: F20-F23 and the passing policy-file cases for `nbv plan --planner policy:FILE`."""
    return list(PART6)


# ---------------------------------------------------------------- part 7: mesh inputs

BOX_V = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (0.0, 1.0)]
BOX_F = [
    (1, 2, 4),
    (1, 4, 3),
    (5, 7, 8),
    (5, 8, 6),
    (1, 5, 6),
    (1, 6, 2),
    (3, 4, 8),
    (3, 8, 7),
    (1, 3, 7),
    (1, 7, 5),
    (2, 6, 8),
    (2, 8, 4),
]
EXPORT, SCAN2 = "nbv scene export model.obj --out D", "nbv scan model.obj circle --views 2 $CAM --out s"


def obj(
    head: str = "",
    faces: list[tuple[int, ...]] | None = None,
    body: str = "",
    name: str = "model.obj",
    texture: str = "",
) -> Callable[[Path], None]:
    """Setup: a unit box OBJ (`head` lines first, `faces` instead of the box's, or `body` instead of all)
    with, when `texture` is a shell snippet, a material whose texture that snippet writes as tex.png."""

    def setup(folder: Path) -> None:
        lines = [f"v {x} {y} {z}" for x, y, z in BOX_V] + [f"vt {u} {v}" for u in (0, 1) for v in (0, 1)]
        lines += ["f " + " ".join(f"{i}/{1 + k % 4}" for k, i in enumerate(f)) for f in (faces or BOX_F)]
        (folder / name).write_text(head + (body or "\n".join(lines)) + "\n")
        if texture:
            (folder / "m.mtl").write_text(f"newmtl a\nKd 1 1 1\n{texture}\n")
            sh(
                '$PYTHON -c "import numpy as n; from PIL import Image; '
                'Image.fromarray((n.indices((64, 64)).sum(0)'
                " % 2 * 255).astype('uint8')).convert('RGB').save('tex.png')\"",
                folder,
            )

    return setup


def textured(map_line: str, make: str = "") -> Callable[[Path], None]:
    """Setup: the box with `mtllib m.mtl`, `usemtl a` and `map_line`, then the shell `make`."""

    def setup(folder: Path) -> None:
        obj("mtllib m.mtl\nusemtl a\n", texture=map_line)(folder)
        if make:
            sh(make, folder)

    return setup


def interleaved(folder: Path) -> None:
    """F26: each face's three vertices, then `f -3 -2 -1`."""
    lines = []
    for face in BOX_F:
        lines += [f"v {BOX_V[i - 1][0]} {BOX_V[i - 1][1]} {BOX_V[i - 1][2]}" for i in face] + ["f -3 -2 -1"]
    (folder / "model.obj").write_text("\n".join(lines) + "\n")


def box_extent(folder: Path, result: Result) -> tuple[str, str] | None:
    """Check: D/mesh.ply spans the unit box (1 x 1 x 1)."""
    import trimesh

    mesh = trimesh.load(folder / "D/mesh.ply", force="mesh", process=False)
    extent = np.ptp(mesh.vertices, axis=0)
    if not np.allclose(sorted(extent), [1, 1, 1], atol=1e-3):
        return "silent", f"wrong geometry: extent {np.round(extent, 3).tolist()}, {len(mesh.faces)} faces"
    return None


def same_texture(folder: Path, result: Result) -> tuple[str, str] | None:
    """Check (F28): the scan with `map_Kd -s ... tex.png` renders as the one with `map_Kd tex.png`."""
    from PIL import Image

    textured("map_Kd tex.png")(folder)
    plain = sh(SCAN2.replace("--out s", "--out plain"), folder, 200)
    if plain.rc != 0:
        return "harness-error", "the plain-texture scan failed: " + plain.last
    if "warn" in result.output.lower():
        return "silent", "a warning for a valid texture: " + result.last
    diffs = [
        np.abs(
            np.asarray(Image.open(folder / f"s/images/{n}")).astype(int)
            - np.asarray(Image.open(folder / f"plain/images/{n}")).astype(int)
        ).max()
        for n in ("0000.png", "0001.png")
    ]
    return ("silent", f"renders differ from map_Kd tex.png by up to {max(diffs)}") if max(diffs) > 3 else None


def ply_ascii(folder: Path) -> None:
    """F29: an ASCII PLY declaring 10^7 faces, with a 12-face body."""
    head = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
    head += "element face 10000000\nproperty list uchar int vertex_indices\nend_header\n"
    body = "".join(f"{x} {y} {z}\n" for x, y, z in BOX_V) + "".join(
        f"3 {a - 1} {b - 1} {c - 1}\n" for a, b, c in BOX_F
    )
    (folder / "model.ply").write_text(head + body)


def ply_binary(folder: Path) -> None:
    """A binary PLY declaring 10^7 faces with a 12-face body (refused since d439c96)."""
    import struct

    head = "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
    head += "property float z\nelement face 10000000\nproperty list uchar int vertex_indices\nend_header\n"
    body = b"".join(struct.pack("<3f", *v) for v in BOX_V)
    body += b"".join(struct.pack("<B3i", 3, a - 1, b - 1, c - 1) for a, b, c in BOX_F)
    (folder / "model.ply").write_bytes(head.encode() + body)


# Part 7: F24-F29 and passing mesh inputs, through `nbv scene export` and `nbv scan`.
degenerate = [(1, 1, 2), (3, 3, 4), (5, 6, 6), (7, 8, 8)]
collinear = "\n".join(
    [f"v {i * 0.01} 0 0" for i in range(102)] + [f"f {i} {i + 1} {i + 2}" for i in range(1, 101)]
)
header30k = (
    "$PYTHON -c \"import struct,zlib;c=lambda k,b:struct.pack('>I',len(b))+k+b+struct.pack('>I',"
    "zlib.crc32(k+b));open('tex.png','wb').write(b'\\x89PNG\\r\\n\\x1a\\n'+c(b'IHDR',struct.pack("
    "'>IIBBBBB',30000,30000,8,2,0,0,0))+c(b'IDAT',zlib.compress(bytes(64)))+c(b'IEND',b''))\""
)
PART7 = [
    Case(
        7,
        "F24-fifo-mtllib",
        EXPORT,
        expect="warn",
        words=("m.mtl",),
        timeout=60,
        setup=lambda f: (obj("mtllib m.mtl\n")(f), os.mkfifo(f / "m.mtl")),
    ),
    Case(
        7,
        "F24-fifo-map_Kd-scan",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        timeout=90,
        setup=textured("map_Kd tex.png", "rm tex.png && mkfifo tex.png"),
    ),
    Case(7, "F25-zero-area-obj", SCAN2, words=("model.obj", "area"), setup=obj(faces=degenerate)),
    Case(7, "F25-collinear-obj", EXPORT, words=("model.obj", "area"), setup=obj(body=collinear)),
    Case(
        7,
        "F25-zero-area-stl",
        "nbv scene export model.stl --out D",
        words=("model.stl", "area"),
        setup='$PYTHON -c "import trimesh,numpy as n;trimesh.Trimesh(n.eye(3),[[0,0,1],[1,1,2]],'
        "process=False).export('model.stl')\"",
    ),
    Case(7, "F26-interleaved-negative", EXPORT, expect="ok", setup=interleaved, check=box_extent),
    Case(
        7,
        "F27-random-bytes-texture",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        setup=textured("map_Kd tex.png", "head -c 5000 /dev/urandom > tex.png"),
    ),
    Case(
        7,
        "F27-png-claims-30000",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        memory=2**31,
        setup=textured("map_Kd tex.png", header30k),
    ),
    Case(
        7,
        "F27-sparse-2GB-texture",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        memory=2**30,
        setup=textured("map_Kd tex.png", "rm tex.png && truncate -s 2G tex.png"),
    ),
    Case(
        7,
        "F28-map_Kd-options",
        SCAN2,
        expect="ok",
        setup=textured("map_Kd -s 2 2 1 -o 0.5 0.5 0 tex.png"),
        check=same_texture,
        timeout=200,
    ),
    Case(
        7,
        "F29-ascii-ply-short",
        "nbv scene export model.ply --out D",
        words=("model.ply",),
        setup=ply_ascii,
    ),
    Case(
        7,
        "binary-ply-short",
        "nbv scene export model.ply --out D",
        words=("model.ply",),
        setup=ply_binary,
    ),
    Case(
        7,
        "plain-negative-indices",
        EXPORT,
        expect="ok",
        check=box_extent,
        setup=obj(
            body="\n".join(
                [f"v {x} {y} {z}" for x, y, z in BOX_V]
                + [f"f {a - 9} {b - 9} {c - 9}" for a, b, c in BOX_F]
            )
        ),
    ),
    Case(7, "valid-box", EXPORT, expect="ok", setup=obj(), check=box_extent),
    Case(7, "index-out-of-range", EXPORT, words=("model.obj",), setup=obj(faces=[(1, 2, 99)] + BOX_F)),
    Case(7, "index-before-start", EXPORT, words=("model.obj",), setup=obj(faces=[(-99, 1, 2)] + BOX_F)),
    Case(
        7,
        "map_Kd-etc-passwd",
        EXPORT,
        expect="warn",
        words=("passwd",),
        setup=textured("map_Kd ../../../../../../etc/passwd"),
    ),
    Case(
        7,
        "missing-texture",
        EXPORT,
        expect="warn",
        words=("nothere.png",),
        setup=textured("map_Kd nothere.png"),
    ),
    Case(7, "empty-obj", EXPORT, words=("model.obj",), setup="touch model.obj"),
    Case(7, "mesh-is-directory", EXPORT, words=("model.obj",), setup="mkdir model.obj"),
    Case(7, "mesh-missing", EXPORT, words=("model.obj",)),
    Case(7, "mesh-fifo", EXPORT, words=("model.obj",), setup="mkfifo model.obj", timeout=60),
    Case(
        7,
        "newline-unicode-name",
        "nbv scene export \"$(printf 'mo\\ndèl.obj')\" --out D",
        expect="either",
        setup=obj(name="mo\ndèl.obj"),
    ),
]


def part7() -> list[Case]:
    """Part 7: F24-F29 and passing mesh inputs, through `nbv scene export` and `nbv scan`."""
    return list(PART7)


# ---------------------------------------------------------------- part 8: bad values



def untouched(path: str) -> Callable[[Path, Result], tuple[str, str] | None]:
    """Check: `path` (in the case folder) was not created."""
    return lambda folder, result: (
        ("silent", f"{path} was written") if os.path.lexists(folder / path) else None
    )


# Part 8: F30-F39 and passing bad values.
long_out = "x" * 5000
PART8 = [
    Case(8, "F30-reconstruct-out-empty", "nbv reconstruct $DS8 --out ''", words=("--out",)),
    Case(8, "F30-scan-out-empty-overwrite", f"{SCAN} --out '' --overwrite", words=("--out",)),
    Case(8, "F30-export-out-empty-overwrite", "nbv export $DS8 --out '' --overwrite", words=("--out",)),
    Case(
        8,
        "F31-train-out-empty",
        f"{TRAIN} --out ''",
        words=("--out",),
        check=untouched("checkpoint.pt"),
        timeout=150,
    ),
    Case(8, "F32-scan-out-5000", f"{SCAN} --out {long_out}", words=("--out",)),
    Case(
        8,
        "F32-reconstruct-out-25x200",
        "nbv reconstruct $DS8 --out " + "/".join(["y" * 200] * 25),
        words=("--out",),
    ),
    Case(8, "F32-train-out-5000", f"{TRAIN} --out {long_out}", words=("--out",), timeout=150),
    Case(
        8,
        "F33-dangling-out",
        "nbv reconstruct $DS8 --out dangling",
        expect="either",
        setup="ln -s nowhere dangling",
    ),
    Case(
        8,
        "F33-dangling-out-overwrite",
        f"{SCAN} --out dangling --overwrite",
        expect="either",
        setup="ln -s nowhere dangling",
    ),
    Case(
        8,
        "F34-metric-points-1e12",
        PLAN2 + " --metric-points 1000000000000",
        words=("--metric-points",),
        memory=2**31,
    ),
    Case(
        8,
        "F34-grid-resolution-1e5",
        "nbv plan test_building --planner infogain --views 2 --no-full-scan $CAM "
        "--out p --grid-resolution 100000",
        words=("--grid-resolution",),
        memory=2**31,
    ),
    Case(
        8,
        "F35-plan-views-1e9",
        PLAN2.replace("--views 2", "--views 1000000000"),
        words=("--views",),
        memory=2**31,
    ),
    Case(
        8, "F36-voxel-1e-9", "nbv reconstruct $DS8 --voxel-size-m 1e-9 --out o", words=("--voxel-size-m",)
    ),
    Case(
        8,
        "F37-export-inside-dataset",
        "nbv export d --out d/images/x --overwrite",
        words=("--out",),
        setup="cp -r $DS8 d",
        check=untouched("d/images/x"),
    ),
    Case(8, "F38-seed-1e3", f"{SCAN} --out s --seed 1e3", words=("--seed",)),
    Case(
        8,
        "F38-width-0x40",
        "nbv scan test_building circle --views 4 --width 0x40 --height 48 --spp 1 --out s",
        words=("--width",),
    ),
    Case(8, "F38-export-seed-neg", "nbv export $DS8 --out e --seed -5", words=("--seed",)),
    Case(8, "F38-plan-seed-neg", PLAN2 + " --seed -5", words=("--seed",)),
    Case(8, "F38-scan-seed-neg", f"{SCAN} --out s --seed -5", words=("--seed",)),
    Case(
        8, "F39-compare-ray-nothing", f"{COMPARE} --ray 127.0.0.1:9", words=("127.0.0.1:9",), timeout=150
    ),
    Case(
        8,
        "F39-train-ray-nothing",
        f"{TRAIN} --collector ray --ray 127.0.0.1:9 --out t",
        words=("127.0.0.1:9",),
        timeout=150,
    ),
    Case(8, "views-neg", "nbv scan test_building circle --views -1 $CAM --out s", words=("--views",)),
    Case(8, "views-0", "nbv scan test_building circle --views 0 $CAM --out s", words=("--views",)),
    Case(
        8, "views-100001", "nbv scan test_building circle --views 100001 $CAM --out s", words=("--views",)
    ),
    Case(8, "focal-1e-300", f"{SCAN} --out s --focal-mm 1e-300", words=("--focal-mm",)),
    Case(
        8,
        "spp-0",
        "nbv scan test_building circle --views 4 --width 64 --height 48 --spp 0 --out s",
        words=("--spp",),
    ),
    Case(8, "near-over-far", f"{SCAN} --out s --near-m 20 --far-m 10", words=("near",)),
    Case(8, "threshold-neg", PLAN2 + " --threshold-cm -1", words=("--threshold-cm",)),
    Case(8, "threshold-nan", PLAN2 + " --threshold-cm nan", words=("--threshold-cm",)),
    Case(8, "candidates-0", PLAN2 + " --candidates 0", words=("--candidates",)),
    Case(8, "metric-points-0", PLAN2 + " --metric-points 0", words=("--metric-points",)),
    Case(8, "gain-ray-stride-0", PLAN2 + " --gain-ray-stride 0", words=("--gain-ray-stride",)),
    Case(
        8, "refine-max-features-0", "nbv refine $DS8 --max-features 0 --out o", words=("--max-features",)
    ),
    Case(8, "refine-words-1e9", "nbv refine $DS8 --words 1000000000 --out o", words=("--words",)),
    Case(8, "compare-workers-0", f"{COMPARE} --workers 0", words=("--workers",)),
    Case(8, "ray-garbage", f"{COMPARE} --ray garbage-address", words=("--ray",), timeout=150),
    Case(8, "out-proc", f"{SCAN} --out /proc/x", words=("--out",)),
    Case(
        8, "cache-dir-is-file", f"NBV_CACHE_DIR=$PWD/f {SCAN} --out s", expect="either", setup="touch f"
    ),
    Case(8, "variant-bogus", f"NBV_VARIANT=bogus {SCAN} --out s", words=("NBV_VARIANT",)),
    Case(8, "seed-2^70", f"{SCAN} --out s --seed {2**70}", expect="either"),
    Case(
        8,
        "width-fullwidth-digits",
        "nbv scan test_building circle --views 4 --width ６４ --height 48 --spp 1 --out s",
        expect="either",
    ),
]


def part8() -> list[Case]:
    """Part 8: F30-F39 and passing bad values."""
    return list(PART8)


ALL_PARTS = (part1, part2, part3, None, part5, part6, part7, part8)


# ---------------------------------------------------------------- driver


def datasets(scratch: Path) -> None:
    """DS8 and DS40 of the report, written once into `scratch`."""
    for views in (8, 40):
        out = scratch / f"DS{views}"
        if not (out / "transforms.json").exists():
            done = sh(
                f"nbv scan test_building circle --views {views} $CAM --out {out} --overwrite", scratch, 600
            )
            if done.rc != 0:
                raise SystemExit(f"DS{views} failed: {done.last}")


def all_cases(scratch: Path) -> list[Case]:
    """Every case, the report's failures (F1-F39) first."""
    cases = [c for part in ALL_PARTS for c in (part() if part else part4(scratch))]
    return sorted(cases, key=lambda c: (not c.id.startswith("F"), c.part))


def counts(records: list[dict]) -> dict[int, dict[str, int]]:
    """Per part: tried and the count of each outcome."""
    table = {}
    for part in PARTS:
        rows = [r for r in records if r["part"] == part]
        table[part] = {
            "tried": len(rows),
            **{o: sum(r["outcome"] == o for r in rows) for o in OUTCOMES},
            "harness-error": sum(r["outcome"] == "harness-error" for r in rows),
        }
    return table


def markdown(table: dict, records: list[dict], commit: str, command: str) -> str:
    """probe.md: the counts per part, then every case."""
    cols = ("tried", *OUTCOMES, "harness-error")
    lines = [
        f"# Reliability probe re-run at {commit}",
        "",
        f"`{command}`",
        "",
        "| part | " + " | ".join(cols) + " |",
        "|---" * (len(cols) + 1) + "|",
    ]
    lines += [f"| {p}. {PARTS[p]} | " + " | ".join(str(table[p][c]) for c in cols) + " |" for p in PARTS]
    total = {c: sum(table[p][c] for p in PARTS) for c in cols}
    lines += [
        "| **total** | " + " | ".join(f"**{total[c]}**" for c in cols) + " |",
        "",
        "| part | case | outcome | command | last line |",
        "|---|---|---|---|---|",
    ]
    esc = lambda s: s.replace("|", "\\|").replace("\n", " ")[:300]  # noqa: E731
    lines += [
        f"| {r['part']} | {r['id']} | {r['outcome']} | `{esc(r['command'])}` | {esc(r['last_line'])} |"
        for r in sorted(records, key=lambda r: (r["part"], r["id"]))
    ]
    return "\n".join(lines) + "\n"


def print_table(table: dict) -> None:
    """The counts per part on stdout."""
    cols = ("tried", *OUTCOMES, "harness-error")
    print(f"{'part':<6}" + "".join(f"{c:>14}" for c in cols))
    for part in PARTS:
        print(f"{part:<6}" + "".join(f"{table[part][c]:>14}" for c in cols))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scratch", type=Path, default=Path("/tmp/reliability-probe"))
    parser.add_argument("--out", type=Path, default=ROOT / "paper_results/reliability")
    parser.add_argument("--only", default="", help="comma-separated case ids or prefixes (e.g. F3,kill-scan)")
    parser.add_argument("--parts", default="", help="comma-separated part numbers")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--timeout-factor", type=float, default=1.0, help="scale every case's timeout")
    args = parser.parse_args(argv)
    args.scratch = args.scratch.resolve()
    args.scratch.mkdir(parents=True, exist_ok=True)
    ENV.update(environment(args.scratch))
    datasets(args.scratch)
    cases = all_cases(args.scratch)
    if args.only:
        cases = [c for c in cases if any(c.id == o or c.id.startswith(o + "-") for o in args.only.split(","))]
    for case in cases:
        case.timeout = int(case.timeout * args.timeout_factor)
    if args.parts:
        cases = [c for c in cases if str(c.part) in args.parts.split(",")]
    commit = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    dirty = bool(
        subprocess.run(
            ["git", "status", "--porcelain"], cwd=ROOT, capture_output=True, text=True
        ).stdout.strip()
    )
    print(f"{len(cases)} cases at {commit}{' (dirty tree)' if dirty else ''}", flush=True)
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        records = list(pool.map(lambda c: run_case(c, args.scratch), cases))
    table = counts(records)
    print_table(table)
    command = "PYTHONPATH=. nice -n 10 python scripts/reliability_probe.py " + " ".join(argv or sys.argv[1:])
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "probe.json").write_text(
        json.dumps(
            {"commit": commit, "dirty_tree": dirty, "command": command, "counts": table, "cases": records},
            indent=1,
        )
        + "\n"
    )
    (args.out / "probe.md").write_text(
        markdown(table, records, commit + (" (dirty)" if dirty else ""), command)
    )
    return 0 if all(r["outcome"] == "passed" for r in records) else 1


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
