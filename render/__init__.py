"""The UAV camera: intrinsics, poses, Mitsuba rendering and settings, scan plans, view datasets, scan cache.

Mitsuba is imported lazily (by `render.renderer`), after the variant and the
libLLVM path are chosen in `render.variant`; names are re-exported lazily too.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "UAVCamera": "render.camera",
    "Viewpoint": "render.viewpoint", "c2w_to_viewpoint": "render.viewpoint",
    "viewpoint_to_c2w": "render.viewpoint",
    "RenderSettings": "render.settings", "LightingSettings": "render.settings",
    "SensorSettings": "render.settings",
    "postprocess": "render.postprocess", "psnr": "render.quality", "ssim": "render.quality",
    "MitsubaRenderer": "render.renderer",
    "CirclePlan": "render.scan", "HemispherePlan": "render.scan", "ScanConfig": "render.scan",
    "circle_scan": "render.scan", "hemisphere_scan": "render.scan",
    "capture_dataset": "render.capture", "scan_dataset": "render.capture",
    "ViewDataset": "render.dataset", "read_dataset": "render.dataset",
    "full_scan": "render.scan_cache",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
