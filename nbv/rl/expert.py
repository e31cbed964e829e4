"""A privileged teacher for training: the step the true surface says is best (beyond the paper; rl.md §4).

The env's actions are small steps (`relative` mode): a constant step is a fixed spiral, which needs no state,
and SAC settles on one whatever the building (paper_results/selection/round6). The teacher reads what a
trained policy may not: the true surface's samples its episode has seen so far. Each of a grid of actions
(`EXPERT_LEVELS` per coordinate) is scored by flying it `horizon` times over (`RewardConfig.teacher_horizon`;
fewer where the budget ends first, 0: to the end of it): for each of those views, the share of samples it is
the first to see times `TEACHER_COVERAGE`, less the flight-cost weight times its leg's metres along the
viewing shell (with a hinge, `nbv.rl.flight_cost`, also its excess weight times the leg's part past the
episode's allowance, counted from the metres already flown), discounted by `discount` per step ahead; ties go
to the shortest flight. One step alone is too short-sighted: where the next 45 degrees hold nothing new, it
hovers (measured on `test_building`: stuck at 86 %). With the horizon at the budget's end and no discount it
is the best spiral from here, chosen again at every view.
Its actions depend on the building by construction; `RewardConfig.imitation` pulls the actor's mode
towards them (`nbv.rl.train.sac_update`), so the actor must read its frames and Bag of Views to follow.
Its best step often beats the runner-up by less than 0.1 coverage points, and the runner-up is often its
mirror (round 19 of paper_results/selection): a squared-error fit to such labels is their mean. With a
`RewardConfig.teacher_tolerance` the term pulls the mode to the nearest of the steps within the tolerance
of the best (`near_best`) instead, and the SAC objective chooses among them.

Example: seen from nowhere yet, the shortest leg that sees the one sample wins (a 45-degree turn, inwards
and a little up, where the shell's arc is shortest).
    >>> import numpy as np
    >>> from nbv.rl.config import EnvConfig
    >>> from nbv.rl.env import action_to_viewpoint
    >>> from render.viewpoint import Viewpoint
    >>> from scenes.spec import SceneSet
    >>> config = EnvConfig(scenes=SceneSet(scene=("test_building",)), action_mode="relative")
    >>> sees = lambda view: np.array([0.5 < view.azimuth < 1.0])  # one sample, a 45-degree step away
    >>> step = lambda action, view: action_to_viewpoint(action, view, config)
    >>> expert_action(Viewpoint(2.0, 0.0, 0.5), np.zeros(1, bool), sees, step, 0.0, 1, 3, 0.9).tolist()
    [-1.0, 0.5, 0.5]
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from nbv.flight.path import shell_path
from nbv.rl.flight_cost import flight_cost
from render.viewpoint import Viewpoint

if TYPE_CHECKING:
    from nbv.rl.config import RewardConfig

EXPERT_LEVELS = (-1.0, -0.5, 0.0, 0.5, 1.0)
"""The action values the teacher tries per coordinate (5^3 = 125 candidate steps)."""
TIE_BREAK_PER_M = 1e-6
"""A flight cost too small to outweigh one new sample: among equal gains the shortest leg wins."""
TEACHER_COVERAGE = 100.0
"""The teacher's weight of new coverage against its flight term (the default's coverage reward weight)."""
EXPERT_KEY = "expert_action"
"""The state's key of the teacher's action (training envs with `RewardConfig.imitation` only)."""
EXPERT_SET_KEY = "expert_near_best"
"""The state's key of the teacher's near-ties, bool (125,) over `CANDIDATES` (`near_best`; training envs
with `RewardConfig.imitation` and a `teacher_tolerance` only)."""


CANDIDATES = np.array(list(itertools.product(EXPERT_LEVELS, repeat=3)))
"""The teacher's candidate actions, (125, 3), in a fixed order (built once, not at every step)."""


def candidate_actions() -> np.ndarray:
    """The teacher's candidate actions, (125, 3), in a fixed order (a copy of `CANDIDATES`)."""
    return CANDIDATES.copy()


def expert_scores(view: Viewpoint, seen: np.ndarray, sees: Callable[[Viewpoint], np.ndarray],
                  step: Callable[[np.ndarray, Viewpoint], Viewpoint], flight_weight: float,
                  views_left: int, horizon: int, discount: float, *, flown_m: float = 0.0,
                  allowance_m: float = 0.0, excess_weight: float = 0.0, pace_m: float = 0.0,
                  weights: np.ndarray | None = None, total: int = 0) -> np.ndarray:
    """Every candidate action's score (module docstring), in `CANDIDATES`' order, from `view`, given the
    samples `seen` so far, what each view `sees`, how an action moves (`step(action, view)`), the flight-cost
    weight per metre, the views still to take, the horizon (0: all of them) and the discount (their defaults
    are `RewardConfig.teacher_horizon` and `teacher_discount`'s), and the hinge's terms (`flight_cost`:
    metres flown so far, the allowance, the excess weight; `pace_m`: the allowance grows by this much each leg
    ahead, a battery spent evenly); float64 (125,), in coverage points. `weights`:
    each sample's worth (None: 1 each); `total`: the samples a coverage point is a hundredth of (0: all of
    `seen`)."""
    horizon = max(1, min(horizon or views_left, views_left))
    per = max(total or len(seen), 1)
    scores = np.empty(len(CANDIDATES))
    for i, action in enumerate(CANDIDATES):
        covered, here, score, flown = seen.copy(), view, 0.0, []
        for k in range(horizon):
            here = step(action, here)
            new = sees(here) & ~covered
            worth = np.count_nonzero(new) if weights is None else weights[new].sum()
            score += discount ** k * TEACHER_COVERAGE * float(worth) / per
            covered |= new
            flown.append(here)
        legs = shell_path(view, flown).legs_m
        before = flown_m + np.cumsum([0.0, *legs[:-1]])  # the episode's metres as each leg starts
        cost = sum(discount ** k * (flight_cost(flight_weight, b, m, allowance_m + k * pace_m, excess_weight)
                                    + TIE_BREAK_PER_M * m) for k, (b, m) in enumerate(zip(before, legs)))
        scores[i] = score - cost
    return scores


def expert_action(view: Viewpoint, seen: np.ndarray, sees: Callable[[Viewpoint], np.ndarray],
                  step: Callable[[np.ndarray, Viewpoint], Viewpoint], flight_weight: float,
                  views_left: int, horizon: int, discount: float, **hinge: float) -> np.ndarray:
    """The candidate action of highest `expert_scores` (the first in the grid's order among equals), its
    arguments the same; float32 (3,) in [-1, 1]."""
    scores = expert_scores(view, seen, sees, step, flight_weight, views_left, horizon, discount, **hinge)
    return best_action(scores)


def best_action(scores: np.ndarray) -> np.ndarray:
    """The candidate of highest score (the first among equals); float32 (3,)."""
    return CANDIDATES[int(np.argmax(scores))].astype(np.float32)


def label_keys(terms: RewardConfig) -> list[str]:
    """The state keys a training env labels with the teacher: none without `imitation`, else its action,
    and its near-ties with a `teacher_tolerance` > 0."""
    if not terms.imitation:
        return []
    return [EXPERT_KEY, EXPERT_SET_KEY] if terms.teacher_tolerance else [EXPERT_KEY]


def near_best(scores: np.ndarray, tolerance: float) -> np.ndarray:
    """Which candidates score within `tolerance` (coverage points) of the best: the teacher's near-ties,
    bool (125,), the best always among them.

    >>> near_best(np.array([1.0, 0.95, 0.5]), 0.1).tolist()
    [True, True, False]
    """
    return scores >= scores.max() - tolerance
