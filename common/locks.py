"""One writer per output: an exclusive lock on each output folder or cache entry while it is written.

The lock is an `flock` on a file `.NAME.lock` beside the output. The kernel drops it when its holder
exits, SIGKILL included, so a dead run never blocks the next one; the holder writes its pid into the
file so that a refused run can name it. A process holds each lock once (`claim` is idempotent): the
early output check and the final swap of one run share it. The file is removed on release; a waiter
that then holds a removed file's lock sees it and locks the new file instead.
"""

from __future__ import annotations

import fcntl
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

WAIT = [False]
"""Whether a run waits for an output another run is writing (`--wait-for-lock`) instead of failing."""
_HELD: dict[Path, int] = {}
"""Locked path (resolved) -> the descriptor of its lock file, for the locks this process holds."""


class OutputBusy(FileExistsError):
    """Another run is writing the output: one line naming it and the holder's pid."""


def lock_file(target: Path) -> Path:
    """The lock file of `target`: `.NAME.lock` beside it."""
    return target.with_name(f".{target.name}.lock")


def claim(target: str | Path, wait: bool | None = None) -> None:
    """Hold the lock of `target` (once per process) until `release`; without `wait` (default: `WAIT`),
    raise OutputBusy naming the holder's pid when another run holds it."""
    target = Path(os.path.realpath(target))
    if target in _HELD:
        return
    target.parent.mkdir(parents=True, exist_ok=True)
    _HELD[target] = _acquire(target, WAIT[0] if wait is None else wait)


def _acquire(target: Path, wait: bool) -> int:
    path = lock_file(target)
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise OutputBusy(f"{target} is being written by another run (pid {holder}); wait for it to "
                             "finish, or pass --wait-for-lock to wait") from None
        try:
            current = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            current = False
        if current:  # else its holder removed it on release between our open and our lock
            with suppress(OSError):  # a full disk: the lock holds without the pid ("pid unknown")
                os.ftruncate(fd, 0)
                os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            return fd
        os.close(fd)


def _holder(fd: int) -> str:
    """The pid in a held lock file (its holder writes it just after locking: give it a moment)."""
    for _ in range(50):
        text = os.pread(fd, 32, 0).decode(errors="replace").strip()
        if text:
            return text
        time.sleep(0.002)
    return "unknown"


def release(target: str | Path) -> None:
    """Give up the lock of `target` if this process holds it (its lock file is removed)."""
    target = Path(os.path.realpath(target))
    fd = _HELD.pop(target, None)
    if fd is not None:
        lock_file(target).unlink(missing_ok=True)
        os.close(fd)


def remove_if_free(path: str | Path) -> None:
    """Remove the lock file `path` if no process holds it (left by a SIGKILLed run); a waiter that
    opened it meanwhile sees it gone and locks a new one."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CLOEXEC)
    except OSError:
        return
    try:
        with suppress(OSError):  # held: its run is alive, and its lock file stays
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            Path(path).unlink(missing_ok=True)
    finally:
        os.close(fd)


def held() -> set[Path]:
    """The paths this process holds locks on."""
    return set(_HELD)


@contextmanager
def lock_scope() -> Iterator[None]:
    """Release, when the block ends, every lock claimed inside it (a command, or one unit of work)."""
    before = held()
    try:
        yield
    finally:
        for target in held() - before:
            release(target)
