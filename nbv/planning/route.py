"""The rest of the flight planned as a whole (round 39; `LookaheadOptions.route`).

The look-ahead (`nbv.planning.lookahead`) scores each next step by what it and two more steps the same way
would see. On the courtyards of validation that flies a low ring first and crowds the high views at the end,
seeing the yard from a few sides only (round 36's diagnosis; rounds 36 and 38 did not mend it). Here every
view still to take is chosen together: a route of forward steps (each an azimuth advance of 27.7 to 55.4
degrees, an absolute radius and elevation: the look-ahead's 125 steps) from the view just flown, scored as one
set, 100 x the weight of the grid's items (unknown voxels, sides never measured) that its views are the first
to reach, over the grid's voxels, less the flight's cost a metre (and the battery's hinge) along the viewing
shell. No step is discounted: the route's last view counts as much as its first.

The search (a local search for an orienteering problem, Vansteenwegen et al., "The orienteering problem: a
survey", EJOR 2011): a greedy route (each step the best gain less its leg's cost given the steps before it),
and the last view's route less the view flown (a warm start), each improved by changing one view at a time
(its radius, elevation and azimuth between its neighbours, the next view kept where it was) while the score
rises; the better route's first view is flown, and the search runs again on the grid that view adds to.

Round 40 (`LookaheadOptions.restarts`): the search also improves routes of steps drawn at random and keeps the
best (a multi-start local search): on validation buildings, eight such starts found routes scoring up to 5 %
more than the greedy and warm routes at the first views of a flight, but flew 0.1 point more coverage at
twice the planning time: not adopted (off in `lookahead-stereo`).
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import product

import numpy as np

from nbv.flight.path import shell_path
from nbv.rl.expert import EXPERT_LEVELS, TEACHER_COVERAGE, TIE_BREAK_PER_M
from nbv.rl.flight_cost import flight_cost
from render.viewpoint import Viewpoint

Step = tuple[int, int, int]
"""A route's step: the levels (indices into `EXPERT_LEVELS`) of its radius, azimuth advance and elevation."""
STEPS: tuple[Step, ...] = tuple(product(range(len(EXPERT_LEVELS)), repeat=3))
"""Every step, in the look-ahead's candidates' order (`nbv.rl.expert.CANDIDATES`)."""
PASSES = 8
"""The most rounds of one-view changes a search makes on a route."""


def view_key(view: Viewpoint) -> tuple[float, float, float]:
    """A view's cache key: radius, azimuth in [0, 2 pi) and elevation, rounded to 1e-9."""
    return round(view.radius, 9), round(view.azimuth % (2 * np.pi), 9), round(view.elevation, 9)


class RouteSearch:
    """One search from the view just flown (module docstring), on the grid as it is after that view."""

    def __init__(self, start: Viewpoint, left: int, sees: Callable[[Viewpoint], np.ndarray],
                 known: np.ndarray, weights: np.ndarray | None,
                 step: Callable[[np.ndarray, Viewpoint], Viewpoint], flight: float, total: int, *,
                 flown_m: float = 0.0, allowance_m: float = 0.0, excess: float = 0.0) -> None:
        """`left` views to take from `start`; `sees(view)`: the items (bool) a view would reach on the grid
        as it is, `known` those already seen, `weights` each item's worth (None: 1 each); `step(action,
        view)`: where an action flies from `view`; the flight's weight a metre, the grid's voxels a coverage
        point is a hundredth of, and the hinge's terms (`flight_cost`: metres flown so far, the battery's
        allowance, the excess weight)."""
        if left < 1:
            raise ValueError(f"a route has at least one view to take, got {left}")
        self.start, self.left, self.sees, self.unknown, self.move = start, left, sees, ~known, step
        self.weights = np.ones(len(known)) if weights is None else weights
        self.flight, self.per, self.flown_m = flight, TEACHER_COVERAGE / max(total, 1), flown_m
        self.allowance_m, self.excess = allowance_m, excess
        self.legs: dict[tuple, float] = {}
        self.reached: dict[tuple, np.ndarray] = {}
        self.counts = np.zeros(len(known), np.int32)

    def reaches(self, view: Viewpoint) -> np.ndarray:
        """The items (indices) `view` would be the first to reach (`sees`, less those `known`), cached."""
        key = view_key(view)
        if key not in self.reached:
            self.reached[key] = np.flatnonzero(self.sees(view) & self.unknown)
        return self.reached[key]

    def next(self, action: Step, view: Viewpoint) -> Viewpoint:
        """Where `action` flies from `view`."""
        return self.move(np.array([EXPERT_LEVELS[i] for i in action]), view)

    def views(self, route: list[Step]) -> list[Viewpoint]:
        """The route's views in order, from the start."""
        views, here = [], self.start
        for action in route:
            here = self.next(action, here)
            views.append(here)
        return views

    def leg(self, a: Viewpoint, b: Viewpoint) -> float:
        """Metres along the viewing shell from `a` to `b` (`shell_path`), cached."""
        key = (view_key(a), view_key(b))
        if key not in self.legs:
            self.legs[key] = shell_path(a, [b]).legs_m[0]
        return self.legs[key]

    def cost(self, views: list[Viewpoint]) -> float:
        """The flight's cost of the route in coverage points: `flight_cost` of each leg after the metres flown
        before it, and `TIE_BREAK_PER_M` a metre."""
        legs = [self.leg(a, b) for a, b in zip([self.start, *views[:-1]], views, strict=True)]
        before = self.flown_m + np.cumsum([0.0, *legs[:-1]])
        return sum(flight_cost(self.flight, b, m, self.allowance_m, self.excess) + TIE_BREAK_PER_M * m
                   for b, m in zip(before, legs, strict=True))

    def gain(self, view: Viewpoint) -> float:
        """Coverage points `view` would add to the route's views counted in `counts`."""
        items = self.reaches(view)
        return self.per * float(self.weights[items[self.counts[items] == 0]].sum())

    def score(self, route: list[Step]) -> float:
        """The route's coverage points (its views' items, each counted once) less its flight's cost."""
        views = self.views(route)
        items = np.unique(np.concatenate([self.reaches(v) for v in views]))
        return self.per * float(self.weights[items].sum()) - self.cost(views)

    def count(self, view: Viewpoint, by: int) -> None:
        """Add `by` to the count of the route's views reaching each item `view` reaches."""
        self.counts[self.reaches(view)] += by

    def greedy(self) -> list[Step]:
        """Each step in turn the one of most gain less its leg's cost, given the steps before it."""
        self.counts[:] = 0
        route, views, here = [], [], self.start
        for _ in range(self.left):
            best = max(STEPS, key=lambda a: self.gain(self.next(a, here))
                       - self.cost([*views, self.next(a, here)]))
            here = self.next(best, here)
            route.append(best)
            views.append(here)
            self.count(here, 1)
        return route

    def improve(self, route: list[Step]) -> list[Step]:
        """Change one view at a time (its radius, elevation, and advance, the next view's advance taking the
        rest so the views after it stay) while that raises the route's score, at most `PASSES` rounds."""
        route, views = list(route), self.views(route)
        self.counts[:] = 0
        for view in views:
            self.count(view, 1)
        for _ in range(PASSES):
            changed = False
            for k in range(len(route)):
                before = self.start if k == 0 else views[k - 1]
                self.count(views[k], -1)
                options = [a for a in STEPS if k == len(route) - 1
                           or 0 <= route[k][1] + route[k + 1][1] - a[1] < len(EXPERT_LEVELS)]

                def worth(action: Step) -> float:
                    moved = self.next(action, before)
                    return self.gain(moved) - self.cost([*views[:k], moved, *views[k + 1:]])

                worths = {action: worth(action) for action in options}  # the current step is among them
                best = max(worths, key=worths.__getitem__)
                if best != route[k] and worths[best] > worths[route[k]] + 1e-9:
                    if k + 1 < len(route):
                        r, a, e = route[k + 1]
                        route[k + 1] = (r, route[k][1] + a - best[1], e)
                    route[k], views[k], changed = best, self.next(best, before), True
                    views[k + 1:] = self.views(route)[k + 1:]
                self.count(views[k], 1)
            if not changed:
                break
        return route

    def best(self, warm: list[Step] | None = None, restarts: int = 0) -> list[Step]:
        """The best of the greedy route, `warm` (the last search's route less its first view) and `restarts`
        routes of steps drawn at random (seeded by the views left, so a flight repeats itself), each
        improved (`improve`); the first of equals."""
        draws = np.random.default_rng(self.left).integers(len(STEPS), size=(restarts, self.left))
        starts = [self.greedy(), *([warm] if warm else []), *([STEPS[i] for i in row] for row in draws)]
        return max((self.improve(route) for route in starts), key=self.score)
