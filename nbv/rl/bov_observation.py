"""What the Bag of Views has seen, a vector beside the frames (`EnvConfig.bov_observation`, beyond the paper).

The paper's state is the last `history` frames and viewpoints: a policy that sees only those cannot tell
which sides of the building the episode has already covered once they leave the history, so it learns
one fixed pattern. This vector is the episode's memory, computed from what the UAV captures (the images,
through the Bag of Views, and the poses flown), so it is available at inference too:

- word fill: each vocabulary's words over W (N x E values, vocabulary r * E + band as the Bag of Views
  orders them: summed over bands they give the per-range fill, over ranges the per-band fill);
- descriptor fill: each vocabulary's remembered descriptors over its memory cap (N x E values): how much
  texture the episode has seen there;
- novelty of the last view: dist(new vocabulary, old) / W, the Bag of Views reward plus 1 over W (1 for a
  view that fills an empty vocabulary, (1 - 1 / c) K / W for one that changes nothing: no descriptors,
  or only what its K words hold already);
- views left: (budget - views so far) / budget, the budget being the episode's views (`episode_views`,
  else the step cap + 1);
- metres flown: the shell path's length so far (`nbv.flight.shell_path`) over one turn of the largest
  ring, 2 pi `radius_max`;
- with `EnvConfig.look_map`, the map of where the episode has looked from (`nbv.rl.look_map`, its
  `LOOK_MAP_SIZE` values);
- with `EnvConfig.privileged_unseen` (a diagnostic that reads the true mesh, never shipped), the map of the
  surface the episode has not seen (`nbv.rl.unseen_map`, its `UNSEEN_MAP_SIZE` values), last.
"""

from __future__ import annotations

import math

import numpy as np

from nbv.bov.bag import BagOfViews
from nbv.rl.config import EnvConfig
from nbv.rl.look_map import LOOK_MAP_SIZE
from nbv.rl.unseen_map import UNSEEN_MAP_SIZE

BOV_KEY = "bov"
"""The state's key of the vector (absent when `EnvConfig.bov_observation` is off)."""
SCALARS = 3
"""Novelty, views left and metres flown, after the two fill grids."""


def bov_observation_size(config: EnvConfig) -> int:
    """Length of the vector for `config` (0 when the option is off: the paper's state)."""
    if not config.bov_observation:
        return 0
    fills = 2 * config.bov.ranges * config.bov.elevation_bands
    return fills + SCALARS + LOOK_MAP_SIZE * config.look_map + UNSEEN_MAP_SIZE * config.privileged_unseen


def view_budget(config: EnvConfig) -> int:
    """Views of an episode, the start view included, that the views-left entry counts down from."""
    return config.episode_views or config.max_steps + 1


def bov_vector(bov: BagOfViews, novelty: float, views: int, metres: float, config: EnvConfig,
               looked: np.ndarray | None = None, unseen: np.ndarray | None = None) -> np.ndarray:
    """The vector (float32, `bov_observation_size(config)`) after `views` views, `metres` flown, the last
    view's novelty `novelty` (`novelty_of`), with `config.look_map` the look map `looked` and with
    `config.privileged_unseen` the unseen map `unseen`."""
    for name, on, given in (("look_map", config.look_map, looked), ("privileged_unseen",
                                                                     config.privileged_unseen, unseen)):
        if on and given is None:
            raise ValueError(f"config.{name} is on: bov_vector needs its map")
    words = bov.word_count.double().numpy() / bov.num_words
    memory = bov.memory_count.double().numpy() / bov.memory_cap
    budget = view_budget(config)
    scalars = [novelty, (budget - views) / budget, metres / (2.0 * math.pi * config.radius_max)]
    parts = [words, memory, scalars] + ([looked] if config.look_map else []) + (
        [unseen] if config.privileged_unseen else [])
    return np.concatenate(parts).astype(np.float32)


def novelty_of(reward: float, bov: BagOfViews) -> float:
    """A view's novelty from its Bag of Views reward: (reward + 1) / W."""
    return (reward + 1.0) / bov.num_words
