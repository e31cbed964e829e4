"""Choosing the Mitsuba variant, once per process (docs/conventions.md).

`cuda_ad_rgb` where a CUDA GPU is present, else `llvm_ad_rgb` where a suitable
libLLVM loads, else `scalar_rgb`. `NBV_VARIANT` (or an explicit argument)
overrides. Dr.Jit 1.5 crashes on Debian's default libLLVM 15 and works with
libLLVM 19, so `DRJIT_LIBLLVM_PATH` is pointed at the newest libLLVM >= 16 found
on the system before Dr.Jit is first imported. Worker processes (ParallelEnv
spawns them) call `select_variant` again: the choice is per process.
"""

from __future__ import annotations

import glob
import os
import re
from functools import cache
from types import ModuleType
from typing import Literal, get_args

Variant = Literal["scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb"]
"""A Mitsuba variant the toolkit supports."""
VARIANTS: tuple[str, ...] = get_args(Variant)
"""Variants the toolkit supports, slowest first."""
_MIN_LLVM = 16
_LLVM_GLOBS = ("/usr/lib/*/libLLVM-*.so", "/usr/lib/*/libLLVM.so.*", "/usr/lib/llvm-*/lib/libLLVM*.so*")


def find_libllvm() -> str | None:
    """Path of the newest libLLVM shared library >= 16 on this system, or None."""
    best: tuple[int, str] | None = None
    for pattern in _LLVM_GLOBS:
        for path in glob.glob(pattern):
            match = re.search(r"libLLVM[-.](?:so\.)?(\d+)", os.path.basename(path))
            if match and int(match.group(1)) >= _MIN_LLVM and (best is None or int(match.group(1)) > best[0]):
                best = (int(match.group(1)), path)
    return best[1] if best else None


def configure_libllvm() -> None:
    """Point Dr.Jit at a working libLLVM unless the user already chose one."""
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        path = find_libllvm()
        if path is not None:
            os.environ["DRJIT_LIBLLVM_PATH"] = path


@cache
def available_variants() -> tuple[str, ...]:
    """The supported variants whose backend works in this process."""
    configure_libllvm()
    import drjit as dr
    import mitsuba as mi

    compiled = set(mi.variants())
    found = ["scalar_rgb"]
    if "llvm_ad_rgb" in compiled and dr.has_backend(dr.JitBackend.LLVM):
        found.append("llvm_ad_rgb")
    if "cuda_ad_rgb" in compiled and dr.has_backend(dr.JitBackend.CUDA):
        found.append("cuda_ad_rgb")
    return tuple(found)


def default_variant() -> str:
    """The fastest available variant: CUDA, then LLVM, then scalar."""
    return available_variants()[-1]


def select_variant(requested: str | None = None) -> ModuleType:
    """Set the Mitsuba variant (`requested`, else `$NBV_VARIANT`, else the default); return `mitsuba`.

    Raises:
        ValueError: the requested variant is unknown or its backend is unavailable here.
    """
    name = requested or os.environ.get("NBV_VARIANT") or default_variant()
    if name not in VARIANTS:
        where = "" if requested else " (from $NBV_VARIANT)"
        raise ValueError(f"unknown Mitsuba variant {name!r}{where}; choose one of {', '.join(VARIANTS)}")
    if name not in available_variants():
        raise ValueError(f"Mitsuba variant {name!r} is not available on this machine "
                         f"(available: {', '.join(available_variants())})")
    import mitsuba as mi

    if mi.variant() != name:
        mi.set_variant(name)
    return mi
