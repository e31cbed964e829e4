"""Part 8: bad command-line values and environment."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from probe.harness import COMPARE, PLAN2, SCAN, TRAIN, Case, Result


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


