"""Beyond one process: units of work and the executor that runs them here, on local workers or on Ray.

Names are re-exported lazily (`common.lazy`); Ray itself is imported only when a run asks for it.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "ExecutorConfig": "nbv.fanout.config",
    "Task": "nbv.fanout.task",
    "WorkerDied": "nbv.fanout.task",
    "run_stages": "nbv.fanout.executor",
    "run_tasks": "nbv.fanout.executor",
    "start_workers": "nbv.fanout.executor",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
