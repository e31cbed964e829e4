"""Next-best-view planners behind one interface, and plan -> capture -> reconstruct -> score.

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "Planner": "nbv.planning.base",
    "make_planner": "nbv.planning.registry",
    "PlannerEntry": "nbv.planning.registry",
    "register": "nbv.planning.registry",
    "InfoGainPlanner": "nbv.planning.infogain",
    "CoverageOraclePlanner": "nbv.planning.oracle",
    "PlanConfig": "nbv.planning.config",
    "PlanSettings": "nbv.planning.config",
    "plan_scan": "nbv.planning.plan",
    "PlanningWorld": "nbv.planning.world",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
