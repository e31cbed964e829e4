"""Units as Ray tasks: on a local Ray instance (`--ray auto`) or a running cluster (`--ray ADDRESS`).

The connection is made once (on first use, or early by `connect`) and kept for
every later stage and call in this process, until it exits, so a study starts
Ray once; Ray keeps its worker processes too. On connecting, one warm-up task
per CPU imports the heavy libraries in the workers (`warm_worker`) while the
caller goes on. Each unit is one Ray task asking for one CPU, so Ray runs as
many at once as the cluster has cores, and each caps Dr.Jit and torch to that
one core (`nbv.fanout.worker`) and takes the caller's `NBV_*` environment. Ray
retries a unit once when its worker dies (`max_retries=1`; exceptions the unit
raises are not retried); a second death is reported by name (`WorkerDied`)
after its partial files are removed. On a cluster the nodes must have this
package installed and share the output folder (and `$NBV_CACHE_DIR`) at the
same path. Ray is imported here only.
"""

from __future__ import annotations

import atexit
import socket
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any

from common.errors import describe
from nbv.fanout.task import Task, WorkerDied, discard_partial
from nbv.fanout.worker import caller_context, run_in_worker, warm_worker

CONNECT_TIMEOUT_S = 5.0
"""Seconds a cluster address (`--ray HOST:PORT`) has to accept a connection before the run fails, naming it
(Ray itself retries for minutes)."""
RETRIES = 1
"""Times a unit is re-run after its worker died."""
_OURS: list[tuple[str, int]] = []
"""The (address, CPUs) of the Ray connection this module made and keeps, if any."""


def connect(address: str, cpus: int) -> ModuleType:
    """Ray, connected: 'auto' starts a local instance with `cpus` CPUs, anything else joins that cluster.
    A connection this module made for other settings is replaced; one made by someone else is used as
    it is. A new connection starts warming one worker per CPU. Returns the `ray` module."""
    if address != "auto":
        check_reachable(address)
    import ray

    wanted = (address, cpus if address == "auto" else 0)
    if ray.is_initialized() and _OURS and _OURS[0] != wanted:
        disconnect()
    if not ray.is_initialized():
        if address == "auto":
            ray.init(address="local", num_cpus=cpus, include_dashboard=False, log_to_driver=False)
        else:
            ray.init(address=address, log_to_driver=False)
        _OURS[:] = [wanted]
        warm = ray.remote(warm_worker).options(num_cpus=1)
        for _ in range(int(ray.cluster_resources().get("CPU", 1))):
            warm.remote(1)
    return ray


def check_reachable(address: str, timeout_s: float = CONNECT_TIMEOUT_S) -> None:
    """Refuse (ValueError naming it) a cluster `address` (HOST:PORT, ray://HOST:PORT) where nothing accepts
    a connection within `timeout_s`; an address of another form is left to Ray to judge."""
    host, colon, port = address.strip().removeprefix("ray://").rpartition(":")
    if not colon or not port.isdigit() or not host:
        return
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s):
            pass
    except OSError as err:
        why = describe(err) if err.errno is not None else "no answer"
        raise ValueError(f"ray {address}: nothing answers at {host}:{port} within {timeout_s:g} s ({why}); "
                         "start the cluster there (`ray start --head`) or use --ray auto") from None


def disconnect() -> None:
    """Shut down the Ray connection this module made (at exit, or to connect elsewhere)."""
    if _OURS:
        import ray

        ray.shutdown()
        _OURS.clear()


atexit.register(disconnect)


def run_on_ray(stages: Sequence[Sequence[Task]], address: str, cpus: int,
               on_done: Callable[[Task], None]) -> None:
    """Run the stages' units as Ray tasks, stage after stage, on the kept connection (`connect`). Raises
    WorkerDied naming a unit whose worker died on its retry too."""
    ray = connect(address, cpus)
    remote = ray.remote(run_in_worker).options(num_cpus=1, max_retries=RETRIES, retry_exceptions=False)
    for stage in stages:
        _run_stage(ray, remote, stage, on_done)


def _run_stage(ray: ModuleType, remote: Any, tasks: Sequence[Task], on_done: Callable[[Task], None]) -> None:
    from ray.exceptions import RayError, RayTaskError

    context = caller_context()
    refs = {remote.remote(task, 1, context, False): task for task in tasks}
    pending = list(refs)
    try:
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
    except BaseException:
        for ref in pending:
            ray.cancel(ref)
        raise
