"""The paper's experiments: its numbers, the demo, Table 2 and planner comparisons (each a config + a run).

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "FullScanStudy": "nbv.experiments.study",
    "DemoConfig": "nbv.experiments.demo",
    "run_demo": "nbv.experiments.demo",
    "TablesConfig": "nbv.experiments.table2",
    "run_tables": "nbv.experiments.table2",
    "CompareConfig": "nbv.experiments.compare",
    "compare_planners": "nbv.experiments.compare",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
