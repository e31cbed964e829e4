"""Reconstruction and evaluation: TSDF fusion, surface metrics, heat maps.

Names are re-exported lazily (`common.lazy`), so importing a config module stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "ReconstructionConfig": "nbv.recon.config",
    "MetricsConfig": "nbv.recon.config",
    "HeatmapConfig": "nbv.recon.config",
    "TSDFFusion": "nbv.recon.tsdf",
    "reconstruct_views": "nbv.recon.tsdf",
    "reconstruct_dataset": "nbv.recon.tsdf",
    "save_reconstruction": "nbv.recon.tsdf",
    "SurfaceMetrics": "nbv.recon.metrics",
    "evaluate_surfaces": "nbv.recon.metrics",
    "write_heatmap": "nbv.recon.heatmap",
    "EvaluateConfig": "nbv.recon.evaluate",
    "ReconstructConfig": "nbv.recon.reconstruct",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
