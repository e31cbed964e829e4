"""A unit of work: a named pure function of its settings that writes its own result files atomically.

Its outcome is what it leaves on disk, never a return value, so a unit run in
this process, in a local worker or on a Ray node leaves the same files, and the
caller reads them back whichever ran it. A unit whose result file is already
there is done and skipped. Results are written atomically (`common.io`), so a
worker killed mid-unit leaves only a dead run's temporary folder, which
`discard_partial` (or the next run writing there) removes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from common.io import recover_stale
from common.locks import lock_scope


class WorkerDied(RuntimeError):
    """A unit's worker process died (killed, out of memory, crashed) on its retry too."""


@dataclass(frozen=True)
class Task:
    """One unit of work: `fn(**kwargs)`, a module-level function (workers import it by name)."""

    name: str
    """Names the unit in progress and error messages, e.g. 'random-seed0 on alpine_chalet'."""
    fn: Callable[..., Any]
    """The work; its return value is dropped (the caller reads `result` back)."""
    kwargs: dict[str, Any] = field(default_factory=dict)
    """Its settings (picklable)."""
    result: Path | None = None
    """The file that exists once the unit is done (it is skipped then); None: an idempotent unit that
    always runs (e.g. one that fills a cache)."""

    def done(self) -> bool:
        """Whether the result file is already there."""
        return self.result is not None and self.result.exists()


def run_task(task: Task) -> None:
    """Run `task` in this process unless it is done; its exceptions carry a note naming it."""
    if task.done():
        return
    try:
        with lock_scope():  # a worker outlives its units: their output locks end with them
            task.fn(**task.kwargs)
    except Exception as err:
        err.add_note(f"in task {task.name!r}")
        raise


def discard_partial(task: Task) -> None:
    """Remove what a dead worker left of `task`: dead runs' temporary files and folders beside its result
    and beside the folder holding it (`common.io.recover_stale`)."""
    if task.result is not None:
        recover_stale(task.result)
        recover_stale(task.result.parent)


def unique_tasks(tasks: Sequence[Task]) -> list[Task]:
    """`tasks` without repeats (same name and settings), in order; ValueError for one name with two
    different settings."""
    seen: dict[str, Task] = {}
    for task in tasks:
        if task.name in seen and seen[task.name] != task:
            raise ValueError(f"two different tasks are both named {task.name!r}")
        seen.setdefault(task.name, task)
    return list(seen.values())
