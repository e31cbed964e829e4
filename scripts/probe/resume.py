"""Part 4: `nbv train` killed or stopped, then resumed, against an uninterrupted run."""

from __future__ import annotations

import random
import shutil
import threading
import time
from collections.abc import Callable
from pathlib import Path

from probe.harness import Case, Result

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


