"""Next-best-view planners behind one interface, and plan -> capture -> reconstruct -> score.

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "Planner": "nbv.planning.planners",
    "make_planner": "nbv.planning.planners",
    "InfoGainPlanner": "nbv.planning.infogain",
    "CoverageOraclePlanner": "nbv.planning.oracle",
    "PlanConfig": "nbv.planning.plan",
    "plan_scan": "nbv.planning.plan",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
