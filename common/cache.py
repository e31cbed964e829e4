"""Writing cache entries: one writer per entry (its lock, `common.locks`), and a failing write only warns.

A cache saves time, nothing more: where an entry cannot be written (a full disk, a read-only cache
folder, a quota), the command warns in one line naming the entry and the errno (once per cache folder),
and goes on with the value it computed. The entries that are files handed on by path (textures) are
written into a temporary folder of this run instead, removed when it exits.
"""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
import warnings
from collections.abc import Callable
from pathlib import Path

from common.errors import describe
from common.io import atomic_path
from common.locks import OutputBusy, claim, release

_SCRATCH: list[Path] = []
"""This run's temporary folder for the files the cache could not keep (made on first need)."""
_WARNED: set[Path] = set()
"""The cache folders a failing write was reported for: one warning per folder, not one per entry."""


def warn_not_written(path: Path, err: BaseException) -> None:
    """Warn, in one line, that the cache entry `path` was not written and why (`describe`: the errno); once
    per cache folder (a full disk fails every entry alike)."""
    if path.parent in _WARNED:
        return
    _WARNED.add(path.parent)
    if isinstance(err, OSError):
        same = err.filename is not None and Path(os.fsdecode(err.filename)) == path
        why = describe(OSError(err.errno, err.strerror) if same and err.errno else err)  # name `path` once
    else:
        why = f"{type(err).__name__}: {str(err).strip()}"
    warnings.warn(f"cache {path} not written ({why.splitlines()[0] if why else ''}); going on without it",
                  stacklevel=3)


def write_cache(path: str | Path, write: Callable[[Path], None]) -> bool:
    """Write the cache file `path` atomically with `write(tmp)`, holding its lock; skipped when another run
    is writing it. A failing write (a full disk) is only a warning. Returns whether the entry was written."""
    path = Path(path)
    try:
        claim(path, wait=False)
    except OutputBusy:
        return False  # another run writes this very entry
    except OSError as err:
        warn_not_written(path, err)
        return False
    try:
        with atomic_path(path) as tmp:
            write(tmp)
        return True
    except Exception as err:  # noqa: BLE001 - torch.save reports a full disk as RuntimeError
        warn_not_written(path, err)
        return False
    finally:
        release(path)


def cache_file(path: str | Path, write: Callable[[Path], None]) -> Path:
    """The cache file `path`, written atomically with `write(tmp)` unless it is there (its lock held: a run
    writing it is waited for). Where it cannot be written, a warning, and the path of a copy written into
    this run's temporary folder instead."""
    path = Path(path)
    for done in (path, *(folder / path.parent.name / path.name for folder in _SCRATCH)):
        if done.is_file():
            return done
    try:
        claim(path, wait=True)
        try:
            if not path.is_file():
                with atomic_path(path) as tmp:
                    write(tmp)
        finally:
            release(path)
        return path
    except OSError as err:
        warn_not_written(path, err)
    fallback = _scratch() / path.parent.name / path.name
    fallback.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(fallback) as tmp:
        write(tmp)
    return fallback


def _scratch() -> Path:
    if not _SCRATCH:
        _SCRATCH.append(Path(tempfile.mkdtemp(prefix="nbv-cache-")))
        atexit.register(shutil.rmtree, _SCRATCH[0], True)
    return _SCRATCH[0]
