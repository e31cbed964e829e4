"""The UAV camera: intrinsics, poses, Mitsuba rendering, scan plans, view datasets.

Mitsuba is imported lazily (by `render.renderer`), after the variant and the
libLLVM path are chosen in `render.variant`.
"""

from render.camera import UAVCamera
from render.viewpoint import Viewpoint, c2w_to_viewpoint, viewpoint_to_c2w

__all__ = ["UAVCamera", "Viewpoint", "c2w_to_viewpoint", "viewpoint_to_c2w"]
