"""`run_stages` and `run_tasks`: run units of work in this process, on local worker processes or on Ray.

The executor only decides where units run: each writes its own files, so the
files (and every number read back from them) are the same whichever runs them.
Units already done are skipped; repeats (same name and settings) run once.
Stages run in order, each once the one before is finished (e.g. a scene's
cached reference, then the runs scored against it). The workers (a local pool
or a Ray connection) live for the whole process: every stage and every call
runs on the same warm ones, and `start_workers` starts them before the first
units come, while the caller sets up.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from nbv.fanout.config import ExecutorConfig
from nbv.fanout.task import Task, run_task, unique_tasks


def start_workers(executor: ExecutorConfig) -> None:
    """Start `executor`'s workers now, warming up in the background (nothing to start in process)."""
    if executor.ray is not None:
        from nbv.fanout.ray_pool import connect

        connect(executor.ray, executor.workers)
    elif executor.workers > 1:
        from nbv.fanout.processes import start_pool

        start_pool(executor.workers)


def run_stages(stages: Sequence[Sequence[Task]], executor: ExecutorConfig = ExecutorConfig(),
               on_done: Callable[[Task], None] | None = None) -> list[Task]:
    """Run the units of each stage not yet done, stage after stage, where `executor` says; `on_done` is
    called as each finishes (in any order within a stage). Returns the units that ran.

    Raises:
        WorkerDied: a unit's worker died on its retry too (named; nothing partial is left).
        ValueError: two different units share a name. A unit's own exception propagates, with a note
            naming it.
    """
    todo = [[task for task in unique_tasks(stage) if not task.done()] for stage in stages]
    todo = [stage for stage in todo if stage]
    done = on_done or (lambda task: None)
    if not todo:
        return []
    if executor.ray is not None:
        from nbv.fanout.ray_pool import run_on_ray

        run_on_ray(todo, executor.ray, executor.workers, done)
    elif executor.workers > 1:
        from nbv.fanout.processes import run_in_processes

        run_in_processes(todo, executor.workers, done)
    else:
        for stage in todo:
            for task in stage:
                run_task(task)
                done(task)
    return [task for stage in todo for task in stage]


def run_tasks(tasks: Sequence[Task], executor: ExecutorConfig = ExecutorConfig(),
              on_done: Callable[[Task], None] | None = None) -> list[Task]:
    """`run_stages` with one stage: run the `tasks` not yet done; return those that ran.

    Example:
        >>> import tempfile
        >>> from pathlib import Path
        >>> from common.io import write_text
        >>> result = Path(tempfile.mkdtemp()) / "a.txt"
        >>> task = Task("a", write_text, {"path": result, "text": "hi"}, result)
        >>> [t.name for t in run_tasks([task, task])], result.read_text(), run_tasks([task])
        (['a'], 'hi', [])
    """
    return run_stages([tasks], executor, on_done)
