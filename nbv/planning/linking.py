"""Registrability as a constraint of the candidate-choosing planners (`--min-matches K`, beyond the paper;
docs/sfm.md §5): a candidate may be flown only if it shares at least K geometrically verified SIFT matches
(`nbv.sfm.links.verified_matches`) with a view already flown, so the flown set stays one connected match
graph, as incremental structure from motion needs.

Greedy, infogain and random apply it: each step they score their candidates (--candidates) as before,
and fly the best scoring of those linked to a flown view (random: the first linked); when none is
linked, the candidate with the most matches to a flown view (the nearest to linked; first on ties). A
candidate is matched with the `link_neighbours` flown views nearest it; one at a viewpoint already
flown is never flown again. With K = 0 none of this runs: the planners choose as before, bit-for-bit.
Fixed patterns (circle, orbits, hemisphere), the policy and the oracle do not take it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from nbv.features.sift import Features
from nbv.sfm.config import LinkSettings
from nbv.sfm.links import verified_matches
from render.viewpoint import Viewpoint, viewpoint_to_c2w

SAME_VIEW_M = 1e-6
"""Camera centres closer than this are one viewpoint (greedy's and infogain's first candidate is the start
view: both draw from the seed's generator first)."""
ORIGIN = np.zeros(3)
"""The centre views are placed about to measure distances between them (any point does: only
differences count)."""


def first_best(scores: Sequence[float]) -> int | None:
    """The index of the first strictly greatest score (the greedy planner's own choice); None when no score
    beats -inf.

    Example:
        >>> first_best([1.0, 3.0, 3.0, 2.0])
        1
    """
    best, index = -math.inf, None
    for i, score in enumerate(scores):
        if score > best:
            best, index = score, i
    return index


def pick_linked(scores: Sequence[float], links: Sequence[int], min_matches: int) -> int | None:
    """The candidate to fly: the first best score among those with >= `min_matches` links; when none has
    them, the first with the most links.

    Example:
        >>> pick_linked([5.0, 9.0, 7.0], [40, 10, 30], 30)   # 1 scores best but is not linked
        2
        >>> pick_linked([5.0, 9.0, 7.0], [4, 10, 10], 30)    # none linked: the most links
        1
    """
    linked = [i for i, n in enumerate(links) if n >= min_matches]
    if not linked:
        return first_best(links)
    found = first_best([scores[i] for i in linked])
    return None if found is None else linked[found]


class FlownLinks:
    """The features of the views flown so far, and how many verified matches a candidate shares with them."""

    def __init__(self, settings: LinkSettings, K: np.ndarray) -> None:  # noqa: N803 - the standard name
        self.settings, self.K = settings, K
        self.centres: list[np.ndarray] = []
        self.features: list[Features] = []

    def add(self, view: Viewpoint, features: Features) -> None:
        """A view just flown, with its features."""
        self.centres.append(viewpoint_to_c2w(view, ORIGIN)[:3, 3])
        self.features.append(features)

    def matches(self, view: Viewpoint, features: Features) -> int:
        """The most verified matches the candidate shares with one of its `link_neighbours` nearest flown
        views; -1 for a candidate at a flown viewpoint (it would link, and add nothing: never flown)."""
        if not self.centres:
            return 0
        distance = np.linalg.norm(np.stack(self.centres) - viewpoint_to_c2w(view, ORIGIN)[:3, 3], axis=1)
        if distance.min() < SAME_VIEW_M:
            return -1
        nearest = np.argsort(distance, kind="stable")[: self.settings.link_neighbours]
        return max(verified_matches(features, self.features[i], self.K) for i in nearest)
