"""Scan plans: the View Planning Toolbox's hemispherical scan and a circular scan (paper Sec. V-B).

Spacing follows photogrammetric end and side overlap under the paper's flat-plane,
small-angle approximations: at distance R an image covers R * W / fx by
R * H / fx metres. Moving along a ring at elevation theta (ring radius
R cos theta) by (1 - end_overlap) of the image width gives the azimuth step
(1 - end_overlap) * (W / fx) / cos(theta); rings are (1 - side_overlap) of the
image height apart, an elevation step of (1 - side_overlap) * H / fx. The
defaults (35 mm lens, 86 % end and 80 % side overlap, elevations 5 to 90
degrees) give 288 views, the paper's count.

Order: rings from the lowest up, each counter-clockwise from azimuth 0; the
single view at the pole (if the rings reach it) comes last.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Annotated, Any

from tyro.conf import subcommand

from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import TWO_PI, Viewpoint
from scenes.spec import SceneSpec

TARGET_REACH_M = 1.0
"""Cameras stay at least this far from the scene centre: a normalised target (largest side 1 m) lies
within 0.9 m of it (half its diagonal), so a closer camera may sit inside the building."""


def check_camera_distance(name: str, radius: float, camera: UAVCamera) -> None:
    """Refuse (ValueError naming `name`) a camera distance inside the target's reach, or too far for the
    camera's far plane to reach the whole target."""
    high = camera.far_m - TARGET_REACH_M
    if not (math.isfinite(radius) and TARGET_REACH_M <= radius <= high):
        raise ValueError(f"{name} must lie in [{TARGET_REACH_M:g}, {high:g}] m (outside the normalised "
                         f"target, whose half-diagonal is under 0.9 m, and within far_m {camera.far_m:g} m "
                         f"of all of it), got {radius}")


@dataclass(frozen=True)
class HemispherePlan:
    """A full-coverage hemisphere scan at constant radius."""

    radius: float = 2.0
    """Distance of every camera from the scene centre, metres."""
    end_overlap: float = 0.86
    """Overlap of consecutive images along a ring, in [0, 1)."""
    side_overlap: float = 0.8
    """Overlap of images on neighbouring rings, in [0, 1)."""
    min_elevation_deg: float = 5.0
    """Elevation of the lowest ring, degrees."""
    max_elevation_deg: float = 90.0
    """Elevation of the highest ring (90: a single view at the pole), degrees."""


@dataclass(frozen=True)
class CirclePlan:
    """One ring of views at a fixed elevation."""

    radius: float = 2.0
    """Distance of every camera from the scene centre, metres."""
    elevation_deg: float = 30.0
    """Elevation of the ring, degrees."""
    views: int | None = 24
    """Number of evenly spaced views; None to derive it from `end_overlap`."""
    end_overlap: float = 0.85
    """Overlap of consecutive images, used when `views` is None."""


MAX_VIEWS = 100_000
"""Most views one scan plan may ask for (a typo's ten million views would run for days)."""


def check_views(name: str, count: int) -> None:
    """Refuse (ValueError naming `name`) a view count below 1 or above `MAX_VIEWS`."""
    if not 1 <= count <= MAX_VIEWS:
        raise ValueError(f"{name} must lie in [1, {MAX_VIEWS}], got {count}")


def _check_overlap(name: str, value: float) -> None:
    if not 0.0 <= value < 1.0:
        raise ValueError(f"{name} must lie in [0, 1), got {value}")


def _check_radius(radius: float) -> None:
    if not (math.isfinite(radius) and radius > 0):
        raise ValueError(f"scan radius must be positive and finite, got {radius}")


def azimuth_step(camera: UAVCamera, end_overlap: float, elevation: float) -> float:
    """Azimuth step (radians) keeping `end_overlap` between neighbours on a ring at `elevation`."""
    _check_overlap("end_overlap", end_overlap)
    return (1.0 - end_overlap) * (camera.width / camera.fx) / max(math.cos(elevation), 1e-9)


def ring(radius: float, elevation: float, count: int) -> list[Viewpoint]:
    """`count` evenly spaced viewpoints on a ring, counter-clockwise from azimuth 0."""
    return [Viewpoint(radius, TWO_PI * k / count, elevation) for k in range(count)]


def hemisphere_scan(camera: UAVCamera, plan: HemispherePlan = HemispherePlan()) -> list[Viewpoint]:
    """Viewpoints of a hemispherical scan with the plan's end and side overlap."""
    _check_radius(plan.radius)
    _check_overlap("side_overlap", plan.side_overlap)
    lo, hi = math.radians(plan.min_elevation_deg), math.radians(plan.max_elevation_deg)
    if not -math.pi / 2 < lo <= hi <= math.pi / 2:
        raise ValueError(f"need -90 < min_elevation_deg <= max_elevation_deg <= 90, got "
                         f"{plan.min_elevation_deg}, {plan.max_elevation_deg}")
    step = (1.0 - plan.side_overlap) * camera.height / camera.fx
    views: list[Viewpoint] = []
    elevation = lo
    while elevation <= hi + 1e-9:
        if math.pi / 2 - elevation < 1e-6:
            views.append(Viewpoint(plan.radius, 0.0, math.pi / 2))
            break
        count = max(math.ceil(TWO_PI / azimuth_step(camera, plan.end_overlap, elevation) - 1e-9), 1)
        check_views("hemisphere views (from end_overlap and side_overlap)", len(views) + count)
        views.extend(ring(plan.radius, elevation, count))
        elevation = min(elevation + step, hi) if elevation < hi - 1e-9 else hi + 1.0
    return views


def circle_scan(camera: UAVCamera, plan: CirclePlan = CirclePlan()) -> list[Viewpoint]:
    """Viewpoints of a circular scan, by view count or by end overlap."""
    _check_radius(plan.radius)
    elevation = math.radians(plan.elevation_deg)
    if not -math.pi / 2 < elevation < math.pi / 2:
        raise ValueError(f"circle elevation_deg must lie in (-90, 90), got {plan.elevation_deg}")
    if plan.views is not None:
        check_views("circle views", plan.views)
        return ring(plan.radius, elevation, plan.views)
    count = math.ceil(TWO_PI / azimuth_step(camera, plan.end_overlap, elevation) - 1e-9)
    check_views("circle views (from end_overlap)", count)
    return ring(plan.radius, elevation, count)


ScanPlan = Annotated[HemispherePlan, subcommand("hemisphere")] | Annotated[CirclePlan, subcommand("circle")]
"""A scan plan, chosen on the command line as a subcommand (`nbv scan SCENE circle --views 8`)."""


def plan_record(plan: HemispherePlan | CirclePlan, views: int) -> dict[str, Any]:
    """A scan plan as recorded in its dataset's `nbv.plan`: its name, its fields and the view count."""
    name = "hemisphere" if isinstance(plan, HemispherePlan) else "circle"
    return {"name": name, **asdict(plan), "views": views}


def plan_viewpoints(camera: UAVCamera, plan: HemispherePlan | CirclePlan) -> list[Viewpoint]:
    """The viewpoints a scan plan asks for."""
    if isinstance(plan, HemispherePlan):
        return hemisphere_scan(camera, plan)
    return circle_scan(camera, plan)


@dataclass(frozen=True, kw_only=True)
class ScanConfig:
    """Settings of `nbv scan`: a scene, a camera, how to render, and the scan plan."""

    scene: SceneSpec
    """The target."""
    out: Path
    """Dataset folder to write (atomically)."""
    camera: UAVCamera = UAVCamera()
    """The camera."""
    render: RenderSettings = RenderSettings()
    """How views are rendered."""
    plan: ScanPlan = HemispherePlan()
    """Scan plan: the full-coverage hemisphere (paper Sec. V-B; the default) or one circle."""
    seed: int = 0
    """Base seed of the per-view render seeds."""
    overwrite: bool = False
    """Replace an existing non-empty output folder (only once the new scan is complete)."""

    def __post_init__(self) -> None:
        check_camera_distance("radius", self.plan.radius, self.camera)
        if isinstance(self.plan, CirclePlan) and self.plan.views is not None:
            check_views("views", self.plan.views)
        if self.seed < 0:
            raise ValueError(f"--seed must be >= 0, got {self.seed}")

    def viewpoints(self) -> list[Viewpoint]:
        """The viewpoints the plan asks for."""
        return plan_viewpoints(self.camera, self.plan)
