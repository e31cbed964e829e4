"""The Bag of Views (paper Sec. III and IV, Alg. 1; docs/bov.md).

N vocabularies, one per azimuth range of width 2pi/N, each of up to W visual
words clustered from a bounded memory of the descriptors the range has taken
in. Dissimilarity of a descriptor and a word is d = 1 - cos / c, where c is the
*match cosine*: a descriptor counts as new (d > 0) when its cosine to the
nearest word is below c. c = 0.5 is the paper's Eq. 1 to the letter
(d = 1 - 2 cos); our default is c = 0.78 (`DEFAULT_MATCH_COSINE`).

Why the departure from docs/bov.md (d = 1 - 2 cos): SIFT descriptors are
non-negative, so even unrelated patches have cosines near 0.5 and a descriptor's
nearest word has cosine 0.7 to 0.8 in a view of another side of the building
(0.98 in the next view of a dense scan). With c = 0.5 every view after the first
of its range scores negative: on 288-view scans of our presets refinement kept
exactly N views for every W, and Table 2's trend (more words keep fewer views)
cannot appear. With c = 0.78 the same scans (the detailed look) keep views over
N in {5..11}, W in {10, 20, 30} closest to the paper's Table 2 (23 to 146), fewer
as W grows and nearly independent of N; the rule is sharp in c (docs/bov.md §4,
paper_results/match_cosine). Pass `match_cosine=0.5` for the literal rule.

Rules (docs/bov.md, where the paper is open):

- Score of a view for range r (Alg. 1 lines 6-9, Sec. III step 2.I): the sum
  over its descriptors of d(descriptor, nearest word of r). An empty vocabulary
  scores +inf; a view with no descriptors scores 0 (even in an empty range).
- Refinement keeps a view iff its score > 0 (Alg. 1 line 10); a kept view joins
  range r's memory and r is re-clustered (lines 11-12); a dropped view changes
  nothing (line 14).
- Update: spherical k-means with K = min(W, descriptors held), k-means++ seeding
  warm-started from the previous words, seeded per (seed, range, update count).
- Memory: a reservoir sample (Algorithm R) of at most `memory_cap` descriptors
  per range, a uniform sample of all the range has seen, so the cost per view
  is bounded however many views pass.
- Reward (Sec. IV, Eq. 3): update the range with the view, then
  r = sum_i d(new_i, nearest old word) - 1 over the new words; W when
  the range was empty (every word new), 0 when it stays empty.
  Identical vocabularies give -K, so an uninformative view earns -K - 1.

Hand-worked toy (N = 2 ranges [0, pi) and [pi, 2pi), W = 1, 4-d descriptors,
e_i the unit vectors, the paper's c = 0.5; tested in tests/nbv/bov/test_bag.py):

=====  =======  ========  =============================  =======================
view   azimuth  features  score                          decision, range 0 word
=====  =======  ========  =============================  =======================
0      0.5      e1, e2    range 0 empty: +inf            kept; (e1 + e2) / sqrt 2
1      1.0      e1        1 - 2 / sqrt 2 = -0.4142       dropped
2      4.0      none      0 (no keypoints)               dropped (range 1 empty)
3      2.0      e3        1 - 2 * 0 = 1                  kept; (e1+e2+e3) / sqrt 3
4      3.5      e4        range 1 empty: +inf            kept; range 1 word e4
=====  =======  ========  =============================  =======================

kept = [0, 3, 4]. Then `reward(e4, azimuth 2.5)`: range 0 holds e1, e2, e3, e4,
its new word is (1, 1, 1, 1) / 2, cos(new, old) = 3 / (2 sqrt 3) = sqrt 3 / 2,
so r = (1 - sqrt 3) - 1 = -sqrt 3 = -1.7321. A reward in an empty range
(N = 2, W = 1, fresh) is W - 1 = 0.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from nbv.bov.config import (
    DEFAULT_KMEANS_ITERS,
    DEFAULT_MATCH_COSINE,
    DEFAULT_MEMORY_CAP,
    BoVConfig,
    BoVRule,
)
from nbv.bov.kmeans import spherical_kmeans
from render.viewpoint import TWO_PI

PAPER_MATCH_COSINE = 0.5
"""c of the paper's Eq. 1 read literally: d = 1 - 2 cos."""


def dissimilarity(cos: torch.Tensor, match_cosine: float = DEFAULT_MATCH_COSINE) -> torch.Tensor:
    """d = 1 - cos / c (paper Eq. 1 when c = 0.5): positive for a cosine below the match cosine c."""
    if not 0.0 < match_cosine <= 1.0:
        raise ValueError(f"match_cosine must lie in (0, 1], got {match_cosine}")
    return 1.0 - cos / match_cosine


def quantize_cosine(x: torch.Tensor, words: torch.Tensor,
                    word_mask: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """Nearest word of each descriptor by cosine (paper Eq. 2, Alg. 1 line 8), in one batched matmul.

    Args:
        x: descriptors, any norm (normalised here).
        words: vocabularies, padded to W words.
        word_mask: True for real words; None means all are real.

    Returns:
        (idx, cos): index of the nearest real word (-1 when a vocabulary has none)
        and its cosine (-inf when none).

    Shape:
        - x: :math:`(*, M, D)`, words: :math:`(*, W, D)`, word_mask: :math:`(*, W)`.
        - idx, cos: :math:`(*, M)`.

    Example:
        >>> idx, cos = quantize_cosine(torch.tensor([[1., 0.]]), torch.tensor([[0., 1.], [1., 1.]]))
        >>> idx.tolist(), round(cos.item(), 4)
        ([1], 0.7071)
    """
    if x.shape[-1] != words.shape[-1]:
        raise ValueError(f"descriptor dim {x.shape[-1]} != word dim {words.shape[-1]}")
    sims = F.normalize(x, dim=-1) @ F.normalize(words, dim=-1).transpose(-1, -2)
    if word_mask is not None:
        sims = sims.masked_fill(~word_mask.unsqueeze(-2), float("-inf"))
    if sims.shape[-1] == 0:
        shape = sims.shape[:-1]
        return (torch.full(shape, -1, dtype=torch.long, device=x.device),
                torch.full(shape, float("-inf"), dtype=sims.dtype, device=x.device))
    cos, idx = sims.max(dim=-1)
    return torch.where(torch.isinf(cos), torch.full_like(idx, -1), idx), cos


def view_score(x: torch.Tensor, words: torch.Tensor, x_mask: torch.Tensor | None = None,
               word_mask: torch.Tensor | None = None,
               match_cosine: float = DEFAULT_MATCH_COSINE) -> torch.Tensor:
    """Alg. 1 score: sum over real descriptors of d(descriptor, nearest word), d = 1 - cos / c.

    +inf for a vocabulary with no words (unless the view has no descriptors: 0).

    Args:
        x: descriptors of views, padded to M.
        words: their vocabularies, padded to W.
        x_mask: True for real descriptors.
        word_mask: True for real words.
        match_cosine: c; 0.5 is the paper's d = 1 - 2 cos.

    Shape:
        - x: :math:`(*, M, D)`, words: :math:`(*, W, D)`, masks :math:`(*, M)` and :math:`(*, W)`.
        - output: :math:`(*)`.

    Example:
        >>> view_score(torch.tensor([[1., 0.], [0., 1.]]), torch.tensor([[1., 0.]]), match_cosine=0.5)
        tensor(0.)
    """
    _, cos = quantize_cosine(x, words, word_mask)
    dist = dissimilarity(cos, match_cosine)
    if x_mask is not None:
        dist = torch.where(x_mask, dist, torch.zeros_like(dist))
    return dist.sum(dim=-1)


def vocabulary_distance(new: torch.Tensor, old: torch.Tensor, new_mask: torch.Tensor | None = None,
                        old_mask: torch.Tensor | None = None,
                        match_cosine: float = DEFAULT_MATCH_COSINE) -> torch.Tensor:
    """dist(nu_{t+1}, nu_t) of paper Eq. 3: sum over new words of d(new_i, nearest old word).

    When the old vocabulary is empty every word is new: the distance is W (the
    padded size of `new`), or 0 if `new` is empty too.

    Shape:
        - new: :math:`(*, W, D)`, old: :math:`(*, W', D)`, masks :math:`(*, W)`, :math:`(*, W')`.
        - output: :math:`(*)`.

    Example:
        >>> w = torch.eye(2)
        >>> vocabulary_distance(w, w, match_cosine=0.5), vocabulary_distance(w, w[:0])
        (tensor(-2.), tensor(2.))
    """
    score = view_score(new, old, new_mask, old_mask, match_cosine)
    has_old = old_mask.any(dim=-1) if old_mask is not None else torch.tensor(old.shape[-2] > 0)
    has_new = new_mask.any(dim=-1) if new_mask is not None else torch.tensor(new.shape[-2] > 0)
    full = torch.full_like(score, float(new.shape[-2]))
    return torch.where(has_old, score, torch.where(has_new, full, torch.zeros_like(score)))


def bov_reward(new: torch.Tensor, old: torch.Tensor, new_mask: torch.Tensor | None = None,
               old_mask: torch.Tensor | None = None,
               match_cosine: float = DEFAULT_MATCH_COSINE) -> torch.Tensor:
    """Reward of paper Sec. IV: r_{t+1} = dist(nu_{T_{t+1}}, nu_{T_t}) - 1.

    Shapes as in `vocabulary_distance`.
    """
    return vocabulary_distance(new, old, new_mask, old_mask, match_cosine) - 1.0


def pad_views(descriptors: Sequence[torch.Tensor | np.ndarray], dim: int,
              device: torch.device | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """Stack views of different descriptor counts into a zero-padded batch and its mask.

    Shape:
        - output: :math:`(B, M_{max}, D)` and :math:`(B, M_{max})`.
    """
    views = [check_descriptors(d, dim, device) for d in descriptors]
    m = max((v.shape[0] for v in views), default=0)
    x = torch.zeros(len(views), m, dim, device=device)
    mask = torch.zeros(len(views), m, dtype=torch.bool, device=device)
    for i, v in enumerate(views):
        x[i, : v.shape[0]] = v
        mask[i, : v.shape[0]] = True
    return x, mask


def check_descriptors(descriptors: torch.Tensor | np.ndarray, dim: int,
                      device: torch.device | None = None) -> torch.Tensor:
    """Validate one view's descriptors, (M, dim) finite, and return them as float32 on `device`."""
    x = torch.as_tensor(descriptors)
    if x.ndim != 2 or x.shape[1] != dim:
        raise ValueError(f"descriptors must be (M, {dim}), got shape {tuple(x.shape)}")
    # amax propagates NaN and is ~40x faster than isfinite(x).all() on CPU.
    if not x.is_floating_point() or (x.numel() and not bool(torch.isfinite(x.abs().amax()))):
        raise ValueError("descriptors must be finite floating-point values")
    return x.to(device=device, dtype=torch.float32)


class BagOfViews(nn.Module):
    """Per-azimuth-range visual vocabularies (paper Sec. III), with the Alg. 1 score and Sec. IV reward.

    State lives in fixed-shape buffers, so `state_dict()` saves and loads with
    `torch.load(..., weights_only=True)`: `words` (N, W, D), `word_count` (N,),
    `memory` (N, memory_cap, D), `memory_count` (N,), `seen` (N,) and
    `updates` (N,).

    Args:
        ranges: N, the number of azimuth ranges.
        words: W, the words per range.
        memory_cap: descriptors held per range (reservoir sample).
        seed: seeds the reservoir and k-means++ draws.
        device: torch device of the state.
        dim: descriptor dimension D (128 for SIFT).
        kmeans_iters: maximum Lloyd rounds per update.
        match_cosine: c of d = 1 - cos / c (0.5: the paper's Eq. 1 to the letter).
        bands: elevation bands E per azimuth range (1: the paper's azimuth-only ranges); the
            vocabularies then number N x E, view (phi, theta) filling azimuth range i's band j.
        elevation_bounds: (low, high) radians split into the E bands (needed when E > 1).

    Example:
        >>> bov = BagOfViews(ranges=2, words=1, dim=4, match_cosine=0.5)
        >>> e = torch.eye(4)
        >>> bov.score(e[:2], 0.5)
        inf
        >>> bov.update(e[:2], 0.5)
        >>> round(bov.score(e[:1], 1.0), 4)
        -0.4142
    """

    def __init__(self, ranges: int, words: int, memory_cap: int = DEFAULT_MEMORY_CAP, seed: int = 0,
                 device: str | torch.device | None = None, dim: int = 128,
                 kmeans_iters: int = DEFAULT_KMEANS_ITERS,
                 match_cosine: float = DEFAULT_MATCH_COSINE, bands: int = 1,
                 elevation_bounds: tuple[float, float] | None = None) -> None:
        super().__init__()
        dissimilarity(torch.zeros(()), match_cosine)  # validates c
        checks = (("ranges", ranges), ("words", words), ("dim", dim), ("kmeans_iters", kmeans_iters),
                  ("bands", bands))
        for name, value in checks:
            if value < 1:
                raise ValueError(f"{name} must be >= 1, got {value}")
        if memory_cap < words:
            raise ValueError(f"memory_cap ({memory_cap}) must be >= words ({words})")
        if bands > 1 and not (elevation_bounds and elevation_bounds[0] < elevation_bounds[1]):
            raise ValueError(f"{bands} elevation bands need elevation_bounds (low < high), "
                             f"got {elevation_bounds}")
        self.azimuth_ranges, self.bands, self.elevation_bounds = ranges, bands, elevation_bounds
        ranges *= bands
        self.ranges, self.num_words, self.memory_cap = ranges, words, memory_cap
        self.seed, self.dim, self.kmeans_iters = seed, dim, kmeans_iters
        self.match_cosine = match_cosine
        self.register_buffer("words", torch.zeros(ranges, words, dim, device=device))
        self.register_buffer("word_count", torch.zeros(ranges, dtype=torch.long, device=device))
        self.register_buffer("memory", torch.zeros(ranges, memory_cap, dim, device=device))
        self.register_buffer("memory_count", torch.zeros(ranges, dtype=torch.long, device=device))
        self.register_buffer("seen", torch.zeros(ranges, dtype=torch.long, device=device))
        self.register_buffer("updates", torch.zeros(ranges, dtype=torch.long, device=device))

    @classmethod
    def from_rule(cls, rule: BoVRule, ranges: int, words: int, seed: int = 0,
                  device: str | torch.device | None = None, dim: int = 128, bands: int = 1,
                  elevation_bounds: tuple[float, float] | None = None) -> BagOfViews:
        """An empty Bag of Views of N = `ranges` (x E = `bands`) vocabularies of W = `words` words
        under `rule` (its match cosine, memory cap and k-means rounds)."""
        return cls(ranges, words, rule.memory_cap, seed=seed, device=device, dim=dim,
                   kmeans_iters=rule.kmeans_iters, match_cosine=rule.match_cosine, bands=bands,
                   elevation_bounds=elevation_bounds)

    @classmethod
    def from_config(cls, config: BoVConfig, seed: int = 0, device: str | torch.device | None = None,
                    elevation_bounds: tuple[float, float] | None = None) -> BagOfViews:
        """An empty Bag of Views of `config`'s size and rule (`elevation_bounds`, radians, split into
        its E bands)."""
        return cls.from_rule(config, config.ranges, config.words, seed, device,
                             bands=config.elevation_bands, elevation_bounds=elevation_bounds)

    def extra_repr(self) -> str:
        return (f"ranges={self.azimuth_ranges}, bands={self.bands}, words={self.num_words}, "
                f"memory_cap={self.memory_cap}, dim={self.dim}, match_cosine={self.match_cosine}")

    @property
    def word_mask(self) -> torch.Tensor:
        """(N, W) True where a vocabulary holds a word."""
        return torch.arange(self.num_words, device=self.words.device) < self.word_count[:, None]

    def range_of(self, azimuth: float, elevation: float = 0.0) -> int:
        """Alg. 1 line 4: id = floor(phi / (2pi / N)), phi wrapped to [0, 2pi); with E bands,
        id * E + the band of the elevation (clamped to the bounds)."""
        if not (math.isfinite(azimuth) and math.isfinite(elevation)):
            raise ValueError(f"azimuth and elevation must be finite, got {azimuth}, {elevation}")
        n = self.azimuth_ranges
        r = min(int((azimuth % TWO_PI) / (TWO_PI / n)), n - 1)
        if self.bands == 1:
            return r
        low, high = self.elevation_bounds
        band = int((elevation - low) / (high - low) * self.bands)
        return r * self.bands + min(max(band, 0), self.bands - 1)

    def forward(self, descriptors: torch.Tensor, mask: torch.Tensor, range_ids: torch.Tensor) -> torch.Tensor:
        """Scores of a padded batch of views against their ranges' vocabularies (no update).

        Shape:
            - descriptors: :math:`(B, M, D)`, mask: :math:`(B, M)`, range_ids: :math:`(B,)`.
            - output: :math:`(B,)`.
        """
        words, word_mask = self.words[range_ids], self.word_mask[range_ids]
        return view_score(descriptors, words, mask, word_mask, self.match_cosine)

    def score(self, descriptors: torch.Tensor | np.ndarray, azimuth: float, elevation: float = 0.0) -> float:
        """Alg. 1 score of one view: +inf for an empty range, 0 for no descriptors.

        Shape:
            - descriptors: :math:`(M, D)`.
        """
        x = check_descriptors(descriptors, self.dim, self.words.device)
        r = self.range_of(azimuth, elevation)
        k = int(self.word_count[r])
        if x.shape[0] == 0 or k == 0:  # docs/bov.md §3: no keypoints -> 0; empty vocabulary -> +inf
            return 0.0 if x.shape[0] == 0 else math.inf
        return float(view_score(x, self.words[r, :k], match_cosine=self.match_cosine))

    def scores(self, descriptors: Sequence[torch.Tensor | np.ndarray],
               azimuths: Sequence[float]) -> torch.Tensor:
        """Alg. 1 scores of many views at once, each against its range's current vocabulary.

        Shape:
            - descriptors: B tensors :math:`(M_b, D)`; output: :math:`(B,)`.
        """
        if len(descriptors) != len(azimuths):
            raise ValueError(f"{len(descriptors)} views but {len(azimuths)} azimuths")
        x, mask = pad_views(descriptors, self.dim, self.words.device)
        ids = torch.tensor([self.range_of(a) for a in azimuths], dtype=torch.long, device=self.words.device)
        return self(x, mask, ids)

    def _generator(self, r: int) -> torch.Generator:
        # One stream per (seed, range, update count): the state_dict alone fixes the next draws.
        state = np.random.SeedSequence([self.seed, r, int(self.updates[r])]).generate_state(1)[0]
        return torch.Generator().manual_seed(int(state))

    def _remember(self, r: int, x: torch.Tensor, generator: torch.Generator) -> None:
        # Algorithm R, vectorised: the t-th descriptor seen fills slot t while
        # t < cap, else replaces slot j ~ U{0..t} when j < cap; the last write wins.
        m, cap = x.shape[0], self.memory_cap
        t = int(self.seen[r]) + torch.arange(m, dtype=torch.float64)
        draw = (torch.rand(m, generator=generator, dtype=torch.float64) * (t + 1)).floor()
        slots = torch.where(t < cap, t, draw).long()
        accept = slots < cap
        last = torch.full((cap,), -1, dtype=torch.long)
        last.scatter_reduce_(0, slots[accept], torch.arange(m)[accept], reduce="amax")
        filled = (last >= 0).nonzero().flatten()
        self.memory[r, filled.to(x.device)] = x[last[filled].to(x.device)]
        self.seen[r] += m
        self.memory_count[r] = min(cap, int(self.seen[r]))

    def update(self, descriptors: torch.Tensor | np.ndarray, azimuth: float, elevation: float = 0.0) -> None:
        """Alg. 1 lines 11-12: add the view's descriptors to its range and re-cluster the words.

        A view with no descriptors changes nothing.

        Shape:
            - descriptors: :math:`(M, D)`.
        """
        x = check_descriptors(descriptors, self.dim, self.words.device)
        if x.shape[0] == 0:
            return
        r = self.range_of(azimuth, elevation)
        generator = self._generator(r)
        self._remember(r, F.normalize(x, dim=1), generator)
        held = int(self.memory_count[r])
        k = min(self.num_words, held)
        init = self.words[r, : int(self.word_count[r])]
        centres, _ = spherical_kmeans(self.memory[r, :held], k, init, self.kmeans_iters, generator)
        self.words[r, :k] = centres
        self.word_count[r] = k
        self.updates[r] += 1

    def reward(self, descriptors: torch.Tensor | np.ndarray, azimuth: float, elevation: float = 0.0,
               commit: bool = True) -> float:
        """Paper Sec. IV: update the view's range, return dist(new vocabulary, old) - 1.

        With `commit=False` the reward is the same but the bag is left exactly as it was (a look-ahead:
        only the view's range changes in an update, and its draws depend only on the state, so restoring
        that range's rows restores everything).

        Shape:
            - descriptors: :math:`(M, D)`.
        """
        r = self.range_of(azimuth, elevation)
        old, old_mask = self.words[r].clone(), self.word_mask[r].clone()
        saved = None if commit else [buffer[r].clone() for buffer in self._per_range()]
        self.update(descriptors, azimuth, elevation)
        reward = float(bov_reward(self.words[r], old, self.word_mask[r], old_mask, self.match_cosine))
        if saved is not None:
            for buffer, rows in zip(self._per_range(), saved):
                buffer[r] = rows
        return reward

    def _per_range(self) -> tuple[torch.Tensor, ...]:
        """Every buffer, each indexed by range first: all an update changes."""
        return (self.words, self.word_count, self.memory, self.memory_count, self.seen, self.updates)

    def reset(self) -> None:
        """Forget every vocabulary and memory."""
        for buffer in self.buffers():
            buffer.zero_()
