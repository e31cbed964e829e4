"""Part 2: two writers on one `--out`."""

from __future__ import annotations

import hashlib
import time
from collections.abc import Callable
from pathlib import Path

from probe.harness import Case, Result, classify, digest, sh, start, strays, wait


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


