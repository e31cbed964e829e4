"""Connectivity repair of a kept view set (`nbv refine --min-matches K`, beyond the paper; docs/sfm.md §5).

The paper's rule keeps a view when it brings unseen visual words; nothing ties the kept views together,
and incremental structure from motion registers only views linked to its model by matches. The repair
keeps the paper's set and adds the fewest dropped views it can so every kept view is linked to the first
through views sharing >= K verified matches (the match graph, `nbv.sfm.links.link_graph`):

1. the linked part: the views reachable from the first kept view through chosen views (kept or added);
2. while a kept view lies outside it, the cheapest path from the linked part to any kept view outside
   (a dropped view costs 1, a chosen view 0; Dijkstra, so among equal costs the lowest-numbered view
   is reached first) is taken, and its dropped views are added;
3. a kept view no path reaches is left unlinked (kept, and reported).

Each step joins at least one more kept view at the least cost for that step: the shortest-path heuristic
of the Steiner tree problem (Takahashi and Matsuyama 1980), which is NP-hard to solve exactly.
"""

from __future__ import annotations

import heapq
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from nbv.features.sift import Features
from nbv.sfm.config import LinkSettings
from nbv.sfm.links import link_graph


@dataclass(frozen=True)
class Repair:
    """A kept set made connected."""

    kept: list[int]
    """The repaired set: the paper's kept views and the added ones, in index order."""
    added: list[int]
    """Dropped views added to link the kept ones, in index order."""
    unlinked: list[int]
    """Kept views no path of linked views reaches from the first (kept all the same)."""


def adjacency(views: int, links: dict[tuple[int, int], int], min_matches: int) -> list[list[int]]:
    """Per view, the views it shares at least `min_matches` verified matches with, in index order."""
    near: list[list[int]] = [[] for _ in range(views)]
    for (i, j), matches in sorted(links.items()):
        if matches >= min_matches and i != j:
            near[i].append(j)
            near[j].append(i)
    return [sorted(n) for n in near]


def reached(root: int, chosen: set[int], near: list[list[int]]) -> set[int]:
    """The chosen views reachable from `root` through chosen views."""
    seen, todo = {root}, [root]
    while todo:
        for v in near[todo.pop()]:
            if v in chosen and v not in seen:
                seen.add(v)
                todo.append(v)
    return seen


def cheapest_path(start: set[int], chosen: set[int], targets: set[int], near: list[list[int]]) -> list[int]:
    """The views of the cheapest path from `start` to any of `targets` (a view outside `chosen` costs 1),
    from its first step to the target; [] when none is reachable."""
    best = dict.fromkeys(start, 0)
    parent: dict[int, int] = {}
    heap = [(0, v) for v in sorted(start)]
    while heap:
        cost, v = heapq.heappop(heap)
        if cost > best[v]:
            continue
        if v in targets:
            path = [v]
            while path[-1] in parent:
                path.append(parent[path[-1]])
            return [u for u in reversed(path) if u not in start]
        for u in near[v]:
            step = cost + (u not in chosen)
            if step < best.get(u, step + 1):
                best[u], parent[u] = step, v
                heapq.heappush(heap, (step, u))
    return []


def repair_links(kept: Sequence[int], views: int, links: dict[tuple[int, int], int],
                 min_matches: int) -> Repair:
    """The kept views of `views` made one linked set (module docstring) over the match graph `links`.

    Example: views 0-1-2-3 in a chain, 0 and 3 kept: 1 and 2 are added.
        >>> repair_links([0, 3], 4, {(0, 1): 40, (1, 2): 35, (2, 3): 50, (0, 3): 2}, 30)
        Repair(kept=[0, 1, 2, 3], added=[1, 2], unlinked=[])
    """
    if not kept:
        return Repair([], [], [])
    near = adjacency(views, links, min_matches)
    chosen, added = set(kept), []
    while True:
        linked = reached(kept[0], chosen, near)
        missing = {v for v in kept if v not in linked}
        path = cheapest_path(linked, chosen, missing, near) if missing else []
        if not path:
            break
        new = [v for v in path if v not in chosen]
        added += new
        chosen.update(path)
    return Repair(sorted(chosen), sorted(added), sorted(missing))


def repair_kept(features: Sequence[Features], centres: np.ndarray, K: np.ndarray,  # noqa: N803
                kept: Sequence[int], settings: LinkSettings) -> tuple[Repair, dict[str, Any]]:
    """`repair_links` of the kept views over the match graph of the views' `features` (each matched with
    its `settings.link_neighbours` nearest by camera centre); the repair and its record for refine.json."""
    start = time.perf_counter()
    links = link_graph(features, centres, K, settings.link_neighbours)
    repair = repair_links(list(kept), len(features), links, settings.min_matches)
    record = {"min_matches": settings.min_matches, "link_neighbours": settings.link_neighbours,
              "paper_kept": list(kept), "added": repair.added, "unlinked": repair.unlinked,
              "pairs_matched": len(links),
              "pairs_linked": sum(m >= settings.min_matches for m in links.values()),
              "seconds": round(time.perf_counter() - start, 3)}
    return repair, record
