"""The reward's flight term (beyond the paper): a cost per metre of each leg, and a steeper one beyond an
episode's allowance (a hinge, so the metres a battery allows cost little and the metres past them much).

A leg of `leg_m` metres flown after `before_m` metres of the episode costs `weight x leg_m` plus
`excess_weight x` the part of the leg past `allowance_m`:

    >>> flight_cost(0.25, before_m=10.0, leg_m=4.0, allowance_m=12.0, excess_weight=1.0)  # 2 m past it
    3.0
    >>> flight_cost(0.25, before_m=0.0, leg_m=4.0, allowance_m=12.0, excess_weight=1.0)
    1.0
"""

from __future__ import annotations


def flight_cost(weight: float, before_m: float, leg_m: float, allowance_m: float = 0.0,
                excess_weight: float = 0.0) -> float:
    """The cost (reward units) of a leg of `leg_m` metres after `before_m` metres of the episode: `weight`
    a metre, plus `excess_weight` a metre for its part beyond `allowance_m` metres of the episode."""
    past = max(0.0, before_m + leg_m - allowance_m) - max(0.0, before_m - allowance_m)
    return weight * leg_m + excess_weight * past
