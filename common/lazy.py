"""Lazy re-exports for package `__init__` modules (PEP 562), so `import nbv.rl.config` stays light.

A package re-exports its public names without importing the heavy modules
that define them (torch, torchrl, open3d) until a name is first used.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any


def lazy_exports(package: str, names: dict[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """`__getattr__` and `__dir__` for `package` that import `names[attr]` (a submodule) on first use.

    Example:
        >>> getattr_, dir_ = lazy_exports("common", {"git_commit": ".provenance"})
        >>> getattr_("git_commit").__name__
        'git_commit'
    """

    def __getattr__(attr: str) -> Any:
        if attr not in names:
            raise AttributeError(f"module {package!r} has no attribute {attr!r}")
        return getattr(importlib.import_module(names[attr], package), attr)

    def __dir__() -> list[str]:
        return sorted(names)

    return __getattr__, __dir__
