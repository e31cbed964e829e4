import math

import numpy as np
import pytest

from render.camera import UAVCamera
from render.scan import CirclePlan, HemispherePlan, azimuth_step, circle_scan, hemisphere_scan


def test_default_hemisphere_has_the_papers_288_views():
    views = hemisphere_scan(UAVCamera())
    assert len(views) == 288
    elevations = sorted({round(v.elevation, 9) for v in views})
    assert elevations[0] == pytest.approx(math.radians(5))
    assert elevations[-1] == pytest.approx(math.pi / 2)
    assert all(v.radius == 2.0 for v in views)


def test_hemisphere_spacing_keeps_the_overlaps():
    cam = UAVCamera(320, 240, 35.0)
    plan = HemispherePlan(end_overlap=0.8, side_overlap=0.6)
    views = hemisphere_scan(cam, plan)
    elevations = sorted({round(v.elevation, 9) for v in views})
    side_step = np.diff(elevations)[:-1]  # the last ring is pinned to the pole
    np.testing.assert_allclose(side_step, 0.4 * 240 / cam.fx)
    for el in elevations[:-1]:
        ring = sorted(v.azimuth for v in views if round(v.elevation, 9) == el)
        # Evenly spaced, and never further apart than the overlap allows.
        assert np.ptp(np.diff(ring)) < 1e-9
        assert 2 * math.pi / len(ring) <= azimuth_step(cam, 0.8, el) + 1e-12


def test_circle_by_count_and_by_overlap():
    cam = UAVCamera()
    views = circle_scan(cam, CirclePlan(radius=1.5, elevation_deg=20, views=12))
    assert len(views) == 12
    np.testing.assert_allclose(np.diff([v.azimuth for v in views]), 2 * math.pi / 12)
    by_overlap = circle_scan(cam, CirclePlan(views=None, end_overlap=0.5, elevation_deg=0))
    assert len(by_overlap) == math.ceil(2 * math.pi / (0.5 * 320 / cam.fx))


@pytest.mark.parametrize("plan, message", [
    (HemispherePlan(radius=-1.0), "radius"),
    (HemispherePlan(end_overlap=1.0), "end_overlap"),
    (HemispherePlan(side_overlap=-0.1), "side_overlap"),
    (HemispherePlan(min_elevation_deg=60, max_elevation_deg=30), "elevation"),
])
def test_bad_plans_are_rejected(plan, message):
    with pytest.raises(ValueError, match=message):
        hemisphere_scan(UAVCamera(), plan)
