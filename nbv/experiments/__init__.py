"""The paper's experiments: its numbers, the demo, its tables and figures, planner studies (comparisons,
online evaluation, budget curves: presets of one `PlannerStudy`) and rendering ablations (each a config + a
run).

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "FullScanStudy": "nbv.experiments.study",
    "DemoConfig": "nbv.experiments.demo",
    "run_demo": "nbv.experiments.demo",
    "TablesConfig": "nbv.experiments.table2",
    "run_tables": "nbv.experiments.table2",
    "PaperConfig": "nbv.experiments.paper",
    "run_paper": "nbv.experiments.paper",
    "BudgetConfig": "nbv.experiments.budget",
    "run_budget": "nbv.experiments.budget",
    "AblateConfig": "nbv.experiments.ablate",
    "run_ablations": "nbv.experiments.ablate",
    "CompareConfig": "nbv.experiments.compare",
    "compare_planners": "nbv.experiments.compare",
    "OnlineConfig": "nbv.experiments.online",
    "run_online": "nbv.experiments.online",
    "PlannerStudy": "nbv.experiments.planner_study",
    "run_study": "nbv.experiments.planner_study",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
