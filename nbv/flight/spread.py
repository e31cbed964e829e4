"""Path spread: how far apart one planner's views lie on two buildings flown from the same start (issue 26).

A planner that does not look at what it captures flies the same viewpoints whatever the building: its
spread is 0 m. Positions are metres relative to each building's centre (`shell_position`), so one
viewpoint on two buildings is 0 m apart. Two sequences are compared view by view over their common length.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

import numpy as np

from nbv.flight.path import shell_position
from render.viewpoint import Viewpoint


def path_gap_m(a: Sequence[Viewpoint], b: Sequence[Viewpoint]) -> float:
    """Mean distance (m) between the i-th camera positions of `a` and `b`, over their common length.

    Example:
        >>> path_gap_m([Viewpoint(2.0, 0.0, 0.0)], [Viewpoint(1.5, 0.0, 0.0), Viewpoint(2.0, 1.0, 0.0)])
        0.5
    """
    if not a or not b:
        raise ValueError("a path gap needs at least one view on each path")
    return float(np.mean([np.linalg.norm(shell_position(*p.as_array()) - shell_position(*q.as_array()))
                          for p, q in zip(a, b)]))


def pair_spreads_m(paths: Mapping[str, Mapping[int, Sequence[Viewpoint]]]) -> dict[tuple[str, str], float]:
    """Per pair of buildings, the mean over the start views (seeds) both were flown from of `path_gap_m`.

    `paths[building][seed]` is the sequence flown on `building` from seed `seed`'s start view.
    """
    spreads = {}
    for a, b in itertools.combinations(paths, 2):
        seeds = sorted(set(paths[a]) & set(paths[b]))
        if not seeds:
            raise ValueError(f"{a} and {b} share no start view (seed): their paths cannot be compared")
        spreads[a, b] = float(np.mean([path_gap_m(paths[a][s], paths[b][s]) for s in seeds]))
    return spreads
