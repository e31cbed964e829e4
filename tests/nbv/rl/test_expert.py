"""The privileged teacher of `--imitation` (nbv.rl.expert), against hand-worked cases, in the training env,
and the imitation term of the SAC update."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch
from tensordict import TensorDict

from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
from nbv.rl.builders import make_loss_module, make_optimizers, make_sac_agent
from nbv.rl.config import EnvConfig, LoggerConfig, RewardConfig, TrainConfig
from nbv.rl.env import NBVEnv, action_to_viewpoint
from nbv.rl.expert import (
    EXPERT_KEY,
    EXPERT_SET_KEY,
    candidate_actions,
    expert_action,
    expert_scores,
    label_keys,
    near_best,
)
from nbv.rl.train import IMITATION_FIELD, imitation_loss, mode_distance, sac_update
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import Viewpoint
from scenes.spec import SceneSet

CONFIG = EnvConfig(scenes=SceneSet(scene=("test_building",)), action_mode="relative")
"""Steps of at most a quarter of each range: 90 degrees of azimuth."""
START = Viewpoint(2.0, 0.0, 0.5)
TEACHER = {"horizon": RewardConfig().teacher_horizon, "discount": RewardConfig().teacher_discount}
"""The teacher's default look-ahead (3 steps, 0.9 a step)."""


def step(action: np.ndarray, view: Viewpoint) -> Viewpoint:
    return action_to_viewpoint(action, view, CONFIG)


def sample_at(low_deg: float, high_deg: float):
    """`sees` for one surface sample seen from azimuths strictly between two bounds (degrees)."""
    return lambda view: np.array([low_deg < np.degrees(view.azimuth) < high_deg])


def test_candidates_are_the_grid_of_levels():
    actions = candidate_actions()
    assert actions.shape == (125, 3) and len({tuple(a) for a in actions}) == 125
    assert set(actions.ravel()) == {-1.0, -0.5, 0.0, 0.5, 1.0}


def test_the_shortest_step_that_sees_the_sample_wins():
    # +0.5 turns 45 degrees, +1 turns 90: both see a sample at (30, 100) degrees; the shorter leg wins. The
    # shell's arc is shortest inwards (R 2 -> 1.75 m) and a little up (cos elevation shrinks the turn's
    # arc): 1.29 m, against 1.38 m for the level 45-degree turn at 2 m.
    action = expert_action(START, np.zeros(1, bool), sample_at(30, 100), step, 0.0, views_left=1, **TEACHER)
    assert action.tolist() == [-1.0, 0.5, 0.5]


def test_the_teacher_looks_past_the_next_step():
    # Only azimuths in (150, 200) see the sample: no single step (at most 90 degrees) reaches it, but
    # +1 twice (180) does, and the other way round (-1 twice: 180 too) ties on gain and leg: the first
    # in the grid's order (-1) wins, inwards and up (the shortest leg). It does not hover.
    far = sample_at(150, 200)
    action = expert_action(START, np.zeros(1, bool), far, step, 0.0, views_left=12, **TEACHER)
    assert action.tolist() == [-1.0, -1.0, 1.0]
    # With one view left it cannot get there: every candidate gains nothing and staying put is shortest.
    last = expert_action(START, np.zeros(1, bool), sample_at(150, 200), step, 0.0, views_left=1, **TEACHER)
    assert last.tolist() == [0, 0, 0]


def test_a_seen_sample_counts_nothing_and_a_dear_flight_keeps_it_home():
    seen = np.ones(1, bool)
    assert expert_action(START, seen, sample_at(30, 100), step, 0.0, 12, **TEACHER).tolist() == [0, 0, 0]
    # One sample of one is a gain of 100 (TEACHER_COVERAGE); the shortest leg that sees it is 1.29 m. One
    # view left: that leg alone is paid for.
    unseen, near = np.zeros(1, bool), sample_at(30, 100)
    assert expert_action(START, unseen, near, step, 100.0, 1, **TEACHER).tolist() == [0, 0, 0]
    assert expert_action(START, unseen, near, step, 50.0, 1, **TEACHER).tolist() == [-1, 0.5, 0.5]
    # With more views left the teacher pays for the legs after it too (flying the same step on, discounted
    # by 0.9 and 0.81, each about 1.3 m): at 50 a metre the sample no longer pays for the flight; at 30 it
    # does over three steps, but not over all eleven undiscounted.
    assert expert_action(START, unseen, near, step, 50.0, 12, **TEACHER).tolist() == [0, 0, 0]
    assert expert_action(START, unseen, near, step, 30.0, 12, **TEACHER).tolist() == [-1, 0.5, 1]
    assert expert_action(START, unseen, near, step, 30.0, 12, horizon=0, discount=1.0
                         ).tolist() == [0, 0, 0]


def test_past_its_allowance_the_hinge_keeps_the_teacher_home():
    # The shortest leg that sees the sample is 1.29 m (above) and the sample is worth 100. Within the
    # allowance no metre costs; 9.5 m flown of a 10 m allowance, 0.79 m of the leg are past it: at 100 a
    # metre past, 79 < 100 and it flies; at 150, 118 > 100 and it stays.
    unseen, near = np.zeros(1, bool), sample_at(30, 100)
    hinge = {"allowance_m": 10.0, "excess_weight": 150.0}
    assert expert_action(START, unseen, near, step, 0.0, 1, **TEACHER, flown_m=0.0, **hinge).tolist() == [
        -1, 0.5, 0.5]
    assert expert_action(START, unseen, near, step, 0.0, 1, **TEACHER, flown_m=9.5, **hinge).tolist() == [
        0, 0, 0]
    assert expert_action(START, unseen, near, step, 0.0, 1, **TEACHER, flown_m=9.5, allowance_m=10.0,
                         excess_weight=100.0).tolist() == [-1, 0.5, 0.5]


def tiny_env(**terms) -> NBVEnv:
    config = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                       render=RenderSettings(spp=1),
                       bov=BoVConfig(ranges=4, sift=FeatureConfig(backend="opencv")),
                       obs_size=16, action_mode="relative", episode_views=4)
    return NBVEnv(config, reward_terms=RewardConfig(**terms))


def test_the_training_env_labels_every_state_with_the_teachers_action():
    env = tiny_env(imitation=1.0, teacher_horizon=2, teacher_discount=0.5)
    assert EXPERT_KEY in env.observation_spec.keys()
    td = env.reset()
    for _ in range(3):
        view, seen = env.viewpoint, env._seen.copy()
        assert env.observation_spec[EXPERT_KEY].is_in(td[EXPERT_KEY])
        moves = lambda a, v: action_to_viewpoint(a, v, env.config)  # noqa: E731
        expected = expert_action(view, seen, env.surface_seen, moves, 0.0, 4 - env._steps - 1, 2, 0.5)
        assert td[EXPERT_KEY].tolist() == expected.tolist()
        td = env.step(td.set("action", td[EXPERT_KEY]))["next"]
    # An env without the term has no teacher: it never reads the true mesh for it.
    plain = tiny_env()
    assert EXPERT_KEY not in plain.observation_spec.keys() and EXPERT_KEY not in plain.reset().keys()


def test_the_imitation_term_pulls_the_actors_mode_to_the_teacher():
    env = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48), obs_size=16)
    config = TrainConfig(env=env, logger=LoggerConfig(out=None))
    torch.manual_seed(0)
    actor, critic = make_sac_agent(config.env, config.network)
    loss, _ = make_loss_module(actor, critic, config.optim)
    optim_actor, optim_critic = make_optimizers(loss, config.optim)
    n = 8
    state = {"pixels": torch.randint(0, 255, (n, 5, 16, 16), dtype=torch.uint8),
             "viewpoints": torch.zeros(n, 5, 3)}
    teacher = torch.tensor([0.0, 0.5, -0.5]).expand(n, 3)
    sample = TensorDict({**state, EXPERT_KEY: teacher, "action": torch.zeros(n, 3), "next": TensorDict({
        **state, "reward": torch.zeros(n, 1), "done": torch.zeros(n, 1, dtype=torch.bool),
        "terminated": torch.zeros(n, 1, dtype=torch.bool)}, [n])}, [n])
    before = imitation_loss(loss, sample.clone()).item()
    logged = [sac_update(loss, optim_actor, optim_critic, sample.clone(), imitation=10.0)[IMITATION_FIELD]
              for _ in range(60)]
    assert logged[0] == pytest.approx(before)
    assert imitation_loss(loss, sample.clone()).item() < 0.1 * before
    assert IMITATION_FIELD not in sac_update(loss, optim_actor, optim_critic, sample.clone())


def test_bad_imitation_settings_are_refused():
    with pytest.raises(ValueError, match="imitation must be finite and >= 0"):
        RewardConfig(imitation=-1.0)
    with pytest.raises(ValueError, match="teacher_horizon must be >= 0"):
        RewardConfig(teacher_horizon=-1)
    with pytest.raises(ValueError, match=r"teacher_discount must lie in \(0, 1\]"):
        RewardConfig(teacher_discount=0.0)
    assert replace(RewardConfig(), imitation=2.0).imitation == 2.0


def test_the_teachers_action_is_its_best_scored_candidate_and_its_near_ties_hold_it():
    # From the start, a sample at (150, 200) degrees: +1 or -1 twice both reach it (module test above).
    scores = expert_scores(START, np.zeros(1, bool), sample_at(150, 200), step, 0.0, 12, **TEACHER)
    actions = candidate_actions()
    assert scores.shape == (125,)
    assert expert_action(START, np.zeros(1, bool), sample_at(150, 200), step, 0.0, 12, **TEACHER
                         ).tolist() == actions[np.argmax(scores)].tolist()
    ties = near_best(scores, 0.1)
    # Within 0.1 points: the largest azimuth step either way (a gain of 0.9 x 100 at the second view,
    # less legs of about 1e-6 a metre), whatever the radius and elevation steps; nothing else.
    assert ties[np.argmax(scores)]
    assert set(actions[ties][:, 1].tolist()) == {-1.0, 1.0} and ties.sum() == 50
    # Without a tolerance: the best and its mirror, exactly equal.
    assert actions[near_best(scores, 0.0)].tolist() == [[-1.0, -1.0, 1.0], [-1.0, 1.0, 1.0]]


def test_the_training_env_labels_the_teachers_near_ties_with_a_tolerance():
    env = tiny_env(imitation=1.0, teacher_tolerance=0.5)
    td = env.reset()
    for _ in range(3):
        scores = env.expert_scores()
        assert td[EXPERT_SET_KEY].tolist() == near_best(scores, 0.5).tolist()
        assert td[EXPERT_KEY].tolist() == candidate_actions()[np.argmax(scores)].tolist()
        td = env.step(td.set("action", td[EXPERT_KEY]))["next"]
    assert EXPERT_SET_KEY not in tiny_env(imitation=1.0).reset().keys()


def test_the_labels_follow_the_imitation_and_tolerance_settings_and_the_env_carries_exactly_them():
    labelled = {EXPERT_KEY, EXPERT_SET_KEY}
    for terms, keys in (({}, []), ({"teacher_tolerance": 0.5}, []), ({"imitation": 1.0}, [EXPERT_KEY]),
                        ({"imitation": 1.0, "teacher_tolerance": 0.5}, [EXPERT_KEY, EXPERT_SET_KEY])):
        assert label_keys(RewardConfig(**terms)) == keys
        env = tiny_env(**terms)
        assert labelled & set(env.observation_spec.keys()) == set(keys)
        assert labelled & set(env.reset().keys()) == set(keys)


def test_the_near_tie_distance_is_to_the_nearest_tie():
    # A fixed actor whose mode is 0.8 on every value: the distance to the best step (1, 1, 1) is 3 x 0.04,
    # to the nearest of {(-1, -1, -1), (0.5, 1, 0.5)} 0.09 + 0.04 + 0.09 = 0.22, and a step outside the
    # ties, however near, counts nothing.
    env = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48), obs_size=16)
    actor = make_sac_agent(env, TrainConfig(env=env, logger=LoggerConfig(out=None)).network)[0]
    head = actor.module[0].module.head[2]
    with torch.no_grad():
        head.weight.zero_()
        head.bias.copy_(torch.tensor([np.arctanh(0.8)] * 3 + [0.0] * 3))
    actions = candidate_actions().tolist()
    ties = torch.zeros(1, 125, dtype=torch.bool)
    ties[0, actions.index([-1.0, -1.0, -1.0])] = ties[0, actions.index([0.5, 1.0, 0.5])] = True
    state = {"pixels": torch.zeros(1, 5, 16, 16, dtype=torch.uint8), "viewpoints": torch.zeros(1, 5, 3),
             EXPERT_KEY: torch.ones(1, 3)}
    assert mode_distance(actor, TensorDict(state, [1])).item() == pytest.approx(0.12, abs=1e-5)
    with_ties = TensorDict({**state, EXPERT_SET_KEY: ties}, [1])
    assert mode_distance(actor, with_ties).item() == pytest.approx(0.22, abs=1e-5)


def test_a_negative_tolerance_is_refused():
    with pytest.raises(ValueError, match="teacher_tolerance must be finite and >= 0"):
        RewardConfig(teacher_tolerance=-0.1)


def test_weighted_samples_count_their_worth_over_the_total_given():
    # Two samples every view sees at once, none seen yet: 100 x 2 / 2 points at the first view (later views
    # see nothing new), less a tie-break of 1e-6 a metre. Worth 1 and 0.5 over a total of 1: 150 points.
    both = lambda view: np.ones(2, bool)  # noqa: E731
    plain = expert_scores(START, np.zeros(2, bool), both, step, 0.0, 12, **TEACHER)
    weighted = expert_scores(START, np.zeros(2, bool), both, step, 0.0, 12, **TEACHER,
                             weights=np.array([1.0, 0.5]), total=1)
    assert plain == pytest.approx(np.full(125, 100.0), abs=1e-4)
    assert weighted == pytest.approx(plain + 50.0, abs=1e-9)


def test_a_paced_battery_charges_each_leg_past_its_share_of_it():
    # Nothing to see: a score is minus its flight cost. A 90-degree turn at 2 m and 0.5 rad up is a leg of
    # L = 2 cos(0.5) pi / 2 = 2.757 m along the shell; three of them (discount 0.9) against a 3 m battery
    # charged 1 a metre past it pay 0.9 (2L - 3) + 0.81 L. Paced at 3 m a leg, no leg passes its share; at
    # 2.5 m a leg the second passes 5.5 m by 2L - 5.5 and the third 8 m by 3L - 8.
    nothing = lambda view: np.zeros(1, bool)  # noqa: E731
    turn = candidate_actions().tolist().index([0.0, 1.0, 0.0])
    leg = 2 * np.cos(0.5) * np.pi / 2

    def cost(**pace: float) -> float:
        return -expert_scores(START, np.zeros(1, bool), nothing, step, 0.0, 12, **TEACHER, allowance_m=3.0,
                              excess_weight=1.0, **pace)[turn]

    assert cost() == pytest.approx(0.9 * (2 * leg - 3) + 0.81 * leg, abs=1e-3)
    assert cost(pace_m=3.0) == pytest.approx(0.0, abs=1e-4)
    assert cost(pace_m=2.5) == pytest.approx(0.9 * (2 * leg - 5.5) + 0.81 * (3 * leg - 8), abs=1e-3)
