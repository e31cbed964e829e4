"""Figures: plots only, a leaf that imports nothing of nbv above it.

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "contact_sheet": "nbv.viz.figures",
    "plot_trajectory": "nbv.viz.figures",
    "plot_planner_comparison": "nbv.viz.figures",
    "plot_table2": "nbv.viz.figures",
    "plot_training": "nbv.viz.figures",
    "PlotTrainingConfig": "nbv.viz.figures",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
