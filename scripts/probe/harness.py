"""The probe's harness: cases, running them (niced, timed, RSS-capped), classing their outcomes, and
hashing output folders (parts 1-3)."""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import psutil

ROOT = Path(__file__).resolve().parents[2]
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
        "last_line": last.replace(str(scratch), "SCRATCH")[-400:],  # no machine path in the results
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


