"""Part 1: SIGKILL at random moments, a symlinked `--out`, stale temporary folders."""

from __future__ import annotations

import json
import random
import time
from collections.abc import Callable
from pathlib import Path

from probe.harness import Case, classify, digest, kill_group, same_structure, sh, start, strays


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


