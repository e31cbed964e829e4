"""Next-best-view planning: features, Bag of Views, refinement, RL, reconstruction, metrics.

Subpackages, one concern each: `features`, `bov`, `recon`, `rl`, `planning`,
`experiments`, `viz`, `fanout`, `bench`, `cli`. The main names are re-exported lazily.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "BagOfViews": "nbv.bov.bag", "BoVConfig": "nbv.bov.config", "refine_views": "nbv.bov.refine",
    "extract_features": "nbv.features.sift",
    "TSDFFusion": "nbv.recon.tsdf", "evaluate_surfaces": "nbv.recon.metrics",
    "NBVEnv": "nbv.rl.env", "EnvConfig": "nbv.rl.config",
    "make_planner": "nbv.planning.registry",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
