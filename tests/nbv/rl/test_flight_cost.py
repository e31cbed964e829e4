"""The reward's flight term and its hinge (`nbv.rl.flight_cost`) on hand-worked legs."""

from __future__ import annotations

import pytest

from nbv.rl.flight_cost import flight_cost


def test_below_the_allowance_only_the_linear_weight_counts():
    assert flight_cost(0.5, before_m=2.0, leg_m=3.0, allowance_m=10.0, excess_weight=7.0) == 1.5


def test_a_leg_across_the_allowance_pays_the_excess_on_its_part_past_it():
    # 8 m flown, a 4 m leg, a 10 m allowance: 2 m of the leg are past it.
    assert flight_cost(0.5, 8.0, 4.0, 10.0, 3.0) == pytest.approx(0.5 * 4 + 3.0 * 2)


def test_past_the_allowance_every_metre_pays_both():
    assert flight_cost(0.5, 12.0, 4.0, 10.0, 3.0) == pytest.approx(3.5 * 4)


def test_the_legs_of_an_episode_sum_to_the_cost_of_its_whole_flight():
    legs, before, total = [3.0, 4.0, 5.0, 2.5], 0.0, 0.0
    for leg in legs:
        total += flight_cost(0.2, before, leg, 9.0, 1.0)
        before += leg
    assert total == pytest.approx(0.2 * 14.5 + 1.0 * (14.5 - 9.0))


def test_without_an_allowance_the_excess_is_a_second_linear_weight():
    assert flight_cost(0.2, 5.0, 2.0, excess_weight=1.0) == pytest.approx(2.4)
    assert flight_cost(0.2, 5.0, 2.0) == pytest.approx(0.4)
