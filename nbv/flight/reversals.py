"""Azimuth reversals: how often a view sequence turns back around the target."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.flight.path import azimuth_step
from render.viewpoint import Viewpoint


def azimuth_reversals(views: Sequence[Viewpoint]) -> int:
    """Sign changes of the azimuth step (the shorter arc) between consecutive views; zero steps are skipped.

    Pass the start view first to count a plan's flight. An orbit has none; a back-and-forth sweep one
    per turn-back.

    Example:
        >>> azimuth_reversals([Viewpoint(2.0, a, 0.1) for a in (0.0, 0.5, 1.0, 0.5, 0.5, 1.0)])
        2
    """
    steps = [azimuth_step(a.azimuth, b.azimuth) for a, b in zip(views, views[1:])]
    signs = [step > 0 for step in steps if step != 0.0]
    return sum(1 for a, b in zip(signs, signs[1:]) if a != b)
