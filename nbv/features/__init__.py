"""SIFT features (Kornia, OpenCV) and their on-disk cache.

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "FeatureConfig": "nbv.features.config",
    "Features": "nbv.features.sift",
    "extract_features": "nbv.features.sift",
    "dataset_features": "nbv.features.cache",
    "repeatability": "nbv.features.repeatability",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
