"""Part 3: every command on a full disk (a 3 MiB tmpfs)."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

from probe.harness import ENV, TRAIN, Case, Result, digest


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


def cache_warned(folder: Path, result: Result) -> tuple[str, str] | None:
    """Check: the run went on past its failing cache write, saying so in a line naming the errno."""
    if re.search(r"cache \S+ not written \(no space left on device \(ENOSPC\)", result.output):
        return None
    return "silent", "no warning naming the cache entry and ENOSPC"


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
        expect="ok",
        check=cache_warned,
        setup=tmpfs(8),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F6-scan-cache",
        "NBV_CACHE_DIR=$PWD/small/cache nbv scan test_building circle --views 4 $CAM --out s",
        expect="ok",
        check=cache_warned,
        setup=tmpfs(8),
        teardown=down,
        timeout=200,
    ),
    Case(
        3,
        "F6-plan-cache",
        "NBV_CACHE_DIR=$PWD/small/cache nbv plan test_building --planner circle --views 3 "
        "--no-full-scan $CAM --out p",
        expect="ok",
        check=cache_warned,
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


