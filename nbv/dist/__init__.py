"""Beyond one process: units of work and the executor that runs them here, on local workers or on Ray.

Names are re-exported lazily (`common.lazy`); Ray itself is imported only when a run asks for it.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "ExecutorConfig": "nbv.dist.config",
    "Task": "nbv.dist.task",
    "WorkerDied": "nbv.dist.task",
    "run_tasks": "nbv.dist.executor",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
