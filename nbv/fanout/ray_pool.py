"""Units as Ray tasks: on a local Ray instance (`--ray auto`) or a running cluster (`--ray ADDRESS`).

Each unit is one Ray task asking for one CPU, so Ray runs as many at once as
the cluster has cores, and each caps Dr.Jit and torch to that one core
(`nbv.fanout.worker`). Ray retries a unit once when its worker dies
(`max_retries=1`; exceptions the unit raises are not retried); a second death
is reported by name (`WorkerDied`) after its partial files are removed. On a
cluster the nodes must have this package installed and share the output
folder (and `$NBV_CACHE_DIR`) at the same path. Ray is imported here only.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any

from nbv.fanout.task import Task, WorkerDied, discard_partial
from nbv.fanout.worker import run_in_worker

RETRIES = 1
"""Times a unit is re-run after its worker died."""


def run_on_ray(stages: Sequence[Sequence[Task]], address: str, cpus: int,
               on_done: Callable[[Task], None]) -> None:
    """Run the stages' units as Ray tasks, stage after stage: `address` 'auto' starts a local instance with
    `cpus` CPUs, anything else joins that cluster (a connection this process already has is used as it
    is). Raises WorkerDied naming a unit whose worker died on its retry too."""
    import ray

    connected = not ray.is_initialized()
    if connected:
        if address == "auto":
            ray.init(address="local", num_cpus=cpus, include_dashboard=False, log_to_driver=False)
        else:
            ray.init(address=address, log_to_driver=False)
    try:
        remote = ray.remote(run_in_worker).options(num_cpus=1, max_retries=RETRIES, retry_exceptions=False)
        for stage in stages:
            _run_stage(ray, remote, stage, on_done)
    finally:
        if connected:
            ray.shutdown()


def _run_stage(ray: ModuleType, remote: Any, tasks: Sequence[Task], on_done: Callable[[Task], None]) -> None:
    from ray.exceptions import RayError, RayTaskError

    refs = {remote.remote(task, 1): task for task in tasks}
    pending = list(refs)
    while pending:
        ready, pending = ray.wait(pending, num_returns=1)
        task = refs[ready[0]]
        try:
            ray.get(ready[0])
        except RayTaskError as err:
            raise err.as_instanceof_cause() from None
        except RayError as err:
            discard_partial(task)
            first = (str(err).strip() or type(err).__name__).splitlines()[0]
            raise WorkerDied(f"task {task.name!r}: its Ray worker died {RETRIES + 1} times "
                             f"({type(err).__name__}: {first}); nothing of it was kept") from None
        on_done(task)
