"""The Bag of Views (paper Sec. III-IV): spherical k-means, the bag (Eq. 1-3), refinement (Alg. 1).

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "BagOfViews": "nbv.bov.bag",
    "BoVConfig": "nbv.bov.config",
    "BoVRule": "nbv.bov.config",
    "spherical_kmeans": "nbv.bov.kmeans",
    "refine_views": "nbv.bov.refine",
    "refine_dataset": "nbv.bov.refine",
    "RefineConfig": "nbv.bov.refine",
    "SweepConfig": "nbv.bov.sweep",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
