"""Bag of Views: batched VQ vs brute force, the docstring's hand-worked toy, memory cap, state_dict."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from nbv.bov.bag import (
    PAPER_MATCH_COSINE,
    BagOfViews,
    dissimilarity,
    quantize_cosine,
    view_score,
    vocabulary_distance,
)

E = torch.eye(4)


def rand_unit(n: int, d: int, seed: int) -> torch.Tensor:
    return F.normalize(torch.rand(n, d, generator=torch.Generator().manual_seed(seed)) ** 3, dim=1)


def test_quantize_matches_numpy_brute_force():
    g = torch.Generator().manual_seed(0)
    x = torch.randn(3, 40, 16, generator=g)
    words = torch.randn(3, 6, 16, generator=g)
    mask = torch.tensor([[True] * 6, [True] * 2 + [False] * 4, [False] * 6])
    idx, cos = quantize_cosine(x, words, mask)
    for b in range(3):
        for m in range(40):
            best, best_cos = -1, -np.inf
            for w in range(6):
                if not mask[b, w]:
                    continue
                u, v = x[b, m].double().numpy(), words[b, w].double().numpy()
                c = u @ v / (np.linalg.norm(u) * np.linalg.norm(v))
                if c > best_cos:
                    best, best_cos = w, c
            assert idx[b, m] == best
            expected = pytest.approx(best_cos, abs=1e-5) if best >= 0 else -math.inf
            assert cos[b, m].item() == expected


def test_batched_scores_equal_per_view_scores():
    bov = BagOfViews(ranges=4, words=5, memory_cap=64, dim=16)
    for i in range(6):
        bov.update(rand_unit(20, 16, i), azimuth=i * 1.3)
    views = [rand_unit(m, 16, 100 + m) for m in (7, 0, 15, 3, 30)]
    azimuths = [0.1, 2.0, 3.3, 4.9, 6.0]
    batched = bov.scores(views, azimuths)
    single = torch.tensor([bov.score(v, a) for v, a in zip(views, azimuths)])
    torch.testing.assert_close(batched, single)
    assert batched[1] == 0.0


def test_hand_worked_toy_from_docstring():
    bov = BagOfViews(ranges=2, words=1, dim=4, match_cosine=PAPER_MATCH_COSINE)
    views = [(E[:2], 0.5), (E[:1], 1.0), (E[:0], 4.0), (E[2:3], 2.0), (E[3:4], 3.5)]
    scores, kept = [], []
    for i, (desc, azimuth) in enumerate(views):
        scores.append(bov.score(desc, azimuth))
        if scores[-1] > 0:
            bov.update(desc, azimuth)
            kept.append(i)
    assert scores[0] == math.inf and scores[4] == math.inf
    assert scores[1] == pytest.approx(1 - 2 / math.sqrt(2), abs=1e-6)
    assert scores[2] == 0.0 and scores[3] == pytest.approx(1.0, abs=1e-6)
    assert kept == [0, 3, 4]
    torch.testing.assert_close(bov.words[0, 0], torch.tensor([1.0, 1, 1, 0]) / math.sqrt(3))
    torch.testing.assert_close(bov.words[1, 0], E[3])
    assert bov.reward(E[3:4], 2.5) == pytest.approx(-math.sqrt(3), abs=1e-6)
    torch.testing.assert_close(bov.words[0, 0], torch.full((4,), 0.5))
    assert BagOfViews(ranges=2, words=1, dim=4).reward(E[:1], 0.1) == pytest.approx(0.0)


def test_default_match_cosine_on_the_same_toy():
    # c = 0.78: view 1's cosine 1/sqrt 2 = 0.707 to the word (e1 + e2)/sqrt 2 is below c, so it is new
    # enough: d = 1 - 0.7071 / 0.78 = 0.0934 > 0, and it is kept (the paper's c = 0.5 drops it).
    bov = BagOfViews(ranges=2, words=1, dim=4)
    bov.update(E[:2], 0.5)
    assert bov.score(E[:1], 1.0) == pytest.approx(1 - (1 / math.sqrt(2)) / 0.78, abs=1e-6)
    assert bov.score(F.normalize(E[0] + 0.5 * E[1], dim=0)[None], 1.0) < 0  # cos 1.5 / sqrt 2.5 = 0.95


def test_dissimilarity_generalises_the_papers_equation():
    cos = torch.tensor([-1.0, 0.0, 0.5, 0.8, 1.0])
    torch.testing.assert_close(dissimilarity(cos, PAPER_MATCH_COSINE), 1 - 2 * cos)
    torch.testing.assert_close(dissimilarity(cos, 0.8), torch.tensor([2.25, 1.0, 0.375, 0.0, -0.25]))
    for bad in (0.0, -0.5, 1.5):
        with pytest.raises(ValueError, match="match_cosine"):
            BagOfViews(ranges=1, words=1, match_cosine=bad)


def test_empty_range_and_no_keypoints():
    bov = BagOfViews(ranges=3, words=4, dim=8)
    assert bov.score(rand_unit(5, 8, 0), 1.0) == math.inf
    assert bov.score(torch.zeros(0, 8), 1.0) == 0.0
    bov.update(torch.zeros(0, 8), 1.0)
    assert int(bov.word_count.sum()) == 0 and int(bov.seen.sum()) == 0
    assert bov.reward(torch.zeros(0, 8), 1.0) == -1.0  # the range stays empty: distance 0


def test_reward_of_range_that_was_empty_is_w_minus_one():
    bov = BagOfViews(ranges=2, words=3, dim=8)
    assert bov.reward(rand_unit(10, 8, 0), 0.2) == pytest.approx(3 - 1)
    assert int(bov.word_count[0]) == 3


def toy_bag(memory_cap: int) -> BagOfViews:
    """The docstring's toy after its three kept views (range 0 holds e1, e2, e3; range 1 holds e4)."""
    bov = BagOfViews(ranges=2, words=1, dim=4, memory_cap=memory_cap, match_cosine=PAPER_MATCH_COSINE)
    for desc, azimuth in [(E[:2], 0.5), (E[2:3], 2.0), (E[3:4], 3.5)]:
        bov.update(desc, azimuth)
    return bov


@pytest.mark.parametrize("memory_cap", [2048, 2])  # 2: range 0 is full, so a look-ahead draws a slot
def test_a_look_ahead_reward_leaves_the_bag_as_it_was(memory_cap):
    import copy

    bov = toy_bag(memory_cap)
    before = {k: v.clone() for k, v in bov.state_dict().items()}
    for desc, azimuth in [(E[3:4], 2.5), (E[:1], 4.0), (rand_unit(5, 4, 1), 0.2)]:
        expected = copy.deepcopy(bov).reward(desc, azimuth)
        assert bov.reward(desc, azimuth, commit=False) == expected
        assert all(torch.equal(v, before[k]) for k, v in bov.state_dict().items())


def test_a_look_ahead_is_the_hand_worked_reward_and_a_commit_learns():
    bov = toy_bag(2048)
    assert bov.reward(E[3:4], 2.5, commit=False) == pytest.approx(-math.sqrt(3), abs=1e-6)
    torch.testing.assert_close(bov.words[0, 0], torch.tensor([1.0, 1, 1, 0]) / math.sqrt(3))
    assert bov.reward(E[3:4], 2.5) == pytest.approx(-math.sqrt(3), abs=1e-6)
    torch.testing.assert_close(bov.words[0, 0], torch.full((4,), 0.5))


def test_vocabulary_distance_definitions():
    w = rand_unit(5, 8, 1)
    assert vocabulary_distance(w, w, match_cosine=0.5).item() == pytest.approx(-5.0, abs=1e-5)  # cos 1: -1
    assert vocabulary_distance(w, w[:0]).item() == 5.0
    assert vocabulary_distance(w[:0], w[:0]).item() == 0.0
    ref = sum(1 - 2 * max(float(a @ b) for b in w[:2]) for a in w)
    assert vocabulary_distance(w, w[:2], match_cosine=0.5).item() == pytest.approx(ref, abs=1e-5)


def test_range_of():
    bov = BagOfViews(ranges=4, words=2)
    azimuths = (0.0, 1.6, math.pi, 4.8, 2 * math.pi - 1e-12, -0.1)
    assert [bov.range_of(a) for a in azimuths] == [0, 1, 2, 3, 3, 3]
    with pytest.raises(ValueError, match="finite"):
        bov.range_of(float("nan"))


def test_word_count_is_min_of_w_and_held():
    bov = BagOfViews(ranges=1, words=10, memory_cap=100, dim=8)
    bov.update(rand_unit(4, 8, 0), 0.0)
    assert int(bov.word_count[0]) == 4
    bov.update(rand_unit(30, 8, 1), 0.0)
    assert int(bov.word_count[0]) == 10
    torch.testing.assert_close(bov.words[0].norm(dim=1), torch.ones(10))


def test_memory_stays_under_cap_and_samples_all_views():
    bov = BagOfViews(ranges=2, words=3, memory_cap=50, dim=4)
    for view in range(40):
        desc = torch.zeros(20, 4)
        desc[:, 0], desc[:, 1] = 1.0, view  # second coordinate tags the view
        bov.update(desc, 0.5)
        assert int(bov.memory_count[0]) <= 50 and bov.memory.shape == (2, 50, 4)
    assert int(bov.seen[0]) == 800 and int(bov.memory_count[0]) == 50
    tags = (bov.memory[0, :, 1] / bov.memory[0, :, 0]).round()
    assert tags.min() < 20 <= tags.max()  # a uniform sample: early and late views both held


def test_same_seed_same_state_and_state_dict_round_trip():
    def run(seed: int) -> BagOfViews:
        bov = BagOfViews(ranges=3, words=4, memory_cap=32, seed=seed, dim=8)
        for i in range(8):
            bov.update(rand_unit(12, 8, i), i * 0.9)
        return bov

    a, b, c = run(0), run(0), run(1)
    assert all(torch.equal(x, y) for x, y in zip(a.state_dict().values(), b.state_dict().values()))
    assert not torch.equal(a.memory, c.memory)
    buffer = io.BytesIO()
    torch.save(a.state_dict(), buffer)
    buffer.seek(0)
    restored = BagOfViews(ranges=3, words=4, memory_cap=32, seed=0, dim=8)
    restored.load_state_dict(torch.load(buffer, weights_only=True))
    view = rand_unit(12, 8, 99)
    assert restored.reward(view, 1.0) == a.reward(view, 1.0)
    assert torch.equal(restored.words, a.words)
    restored.reset()
    assert restored.score(view, 1.0) == math.inf


@pytest.mark.parametrize("kwargs", [dict(ranges=0, words=3), dict(ranges=3, words=0),
                                    dict(ranges=2, words=8, memory_cap=4)])
def test_bad_sizes(kwargs):
    with pytest.raises(ValueError):
        BagOfViews(**kwargs)


def test_bad_descriptors():
    bov = BagOfViews(ranges=2, words=2, dim=8)
    with pytest.raises(ValueError, match=r"\(M, 8\)"):
        bov.score(torch.zeros(3, 5), 0.0)
    with pytest.raises(ValueError, match="finite"):
        bov.update(torch.full((2, 8), float("nan")), 0.0)


def test_view_score_masks_padding():
    x = torch.stack([E[:2], torch.stack([E[0], torch.zeros(4)])])
    mask = torch.tensor([[True, True], [True, False]])
    words = E[:1].expand(2, 1, 4)
    torch.testing.assert_close(view_score(x, words, mask, match_cosine=0.5), torch.tensor([-1.0 + 1.0, -1.0]))


def test_elevation_bands_split_each_azimuth_range():
    bov = BagOfViews(ranges=2, words=1, dim=4, bands=2, elevation_bounds=(0.0, 1.0))
    assert bov.ranges == 4 and tuple(bov.words.shape) == (4, 1, 4)
    # id = azimuth range * E + band; elevations outside the bounds clamp to the end bands
    assert [bov.range_of(0.1, e) for e in (-1.0, 0.2, 0.6, 5.0)] == [0, 0, 1, 1]
    assert [bov.range_of(4.0, e) for e in (0.2, 0.6)] == [2, 3]
    bov.update(E[:1], 0.1, 0.2)  # a low view of range 0
    assert bov.score(E[:1], 0.1, 0.2) < 0  # seen again low: not new
    assert bov.score(E[:1], 0.1, 0.8) == math.inf  # the same appearance from high up: a new range
    flat = BagOfViews(ranges=2, words=1, dim=4)
    flat.update(E[:1], 0.1, 0.2)
    assert flat.score(E[:1], 0.1, 0.8) < 0  # the paper's azimuth-only ranges cannot tell them apart
    with pytest.raises(ValueError, match="elevation_bounds"):
        BagOfViews(ranges=2, words=1, bands=2)


def test_bov_config_elevation_bands():
    from nbv.bov.config import BoVConfig

    bag = BagOfViews.from_config(BoVConfig(ranges=8, words=5, elevation_bands=2), elevation_bounds=(0.1, 1.3))
    assert bag.ranges == 16 and bag.bands == 2
    with pytest.raises(ValueError, match="elevation_bands"):
        BoVConfig(elevation_bands=0)


def test_a_bag_from_a_rule_takes_every_knob_of_the_rule():
    from nbv.bov.config import BoVRule

    bag = BagOfViews.from_rule(BoVRule(match_cosine=0.6, memory_cap=64, kmeans_iters=3), 5, 7, seed=2, dim=4)
    assert (bag.ranges, bag.num_words, bag.memory_cap, bag.kmeans_iters) == (5, 7, 64, 3)
    assert (bag.match_cosine, bag.seed, bag.dim, bag.bands) == (0.6, 2, 4, 1)


def test_a_record_of_the_older_flat_feature_settings_reads_as_the_nested_ones():
    from common.provenance import config_from_record, config_record
    from nbv.bov.config import BoVConfig
    from nbv.features.config import FeatureConfig

    old = {"match_cosine": 0.8, "memory_cap": 2048, "kmeans_iters": 10, "features": "opencv",
           "max_features": 300, "ranges": 8, "words": 20, "elevation_bands": 2}  # the shipped policy's layout
    config = BoVConfig(match_cosine=0.8, ranges=8, elevation_bands=2,
                       sift=FeatureConfig(backend="opencv", max_features=300))
    assert config_from_record(BoVConfig, old) == config
    assert config_from_record(BoVConfig, config_record(config)) == config
    with pytest.raises(ValueError, match="no field"):
        config_from_record(BoVConfig, {**old, "feature": "kornia"})
