"""The true surface's unseen share by direction: a privileged diagnostic (`EnvConfig.privileged_unseen`).

The teacher (`nbv.rl.expert`) chooses by which surface samples its episode has not seen yet; its students
sit on a band 1.5 to 3 coverage points under it at the same metres (paper_results/selection/round22). This
map hands a student the same knowledge, summarised: the target's surface samples binned by the azimuth of
their position about the target centre (`UNSEEN_AZIMUTHS` sectors, the first from azimuth 0) and by their
height (`UNSEEN_HEIGHTS` equal bands from the lowest sample to the highest), each bin's value the samples it
holds that the episode has not seen, over the samples an average bin holds (so the map sums to
`UNSEEN_MAP_SIZE` x the unseen share). It reads the true mesh, so a policy that reads it cannot fly a real
building: it answers whether information is what the students lack, and never ships
(`nbv.rl.members.export_run` refuses it).

Example: four samples, two seen; the unseen ones sit in sector 0 of the lowest band and sector 1 of the
highest (each bin's value 1 / (4 / 36) = 9).
    >>> import numpy as np
    >>> samples = np.array([[1.0, 0.1, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 3.0], [1.0, 1.0, 3.0]])
    >>> bins = sample_bins(samples, np.zeros(3))
    >>> bins.tolist()
    [0, 6, 27, 25]
    >>> unseen = unseen_map(bins, np.array([False, True, True, False]))
    >>> np.flatnonzero(unseen).tolist(), unseen[[0, 25]].tolist()
    ([0, 25], [9.0, 9.0])
"""

from __future__ import annotations

import numpy as np

from render.viewpoint import TWO_PI

UNSEEN_AZIMUTHS = 12
"""Azimuth sectors of the map: 30 degrees each, from azimuth 0 (x) counter-clockwise."""
UNSEEN_HEIGHTS = 3
"""Height bands of the map, equal, from the target's lowest surface sample to its highest."""
UNSEEN_MAP_SIZE = UNSEEN_AZIMUTHS * UNSEEN_HEIGHTS
"""Values of the map: band by band (the lowest first), sector by sector within a band."""


def sample_bins(samples: np.ndarray, center: np.ndarray) -> np.ndarray:
    """Each surface sample's bin of the map (int64 (N,)): band x `UNSEEN_AZIMUTHS` + sector, the sector
    by the azimuth of the sample's position about `center`, the band by its height (z up)."""
    offset = np.asarray(samples, dtype=np.float64) - np.asarray(center, dtype=np.float64)
    azimuth = np.arctan2(offset[:, 1], offset[:, 0]) % TWO_PI
    sector = np.minimum((azimuth * (UNSEEN_AZIMUTHS / TWO_PI)).astype(np.int64), UNSEEN_AZIMUTHS - 1)
    z = offset[:, 2]
    span = max(float(z.max() - z.min()), 1e-9)
    band = np.minimum(((z - z.min()) * (UNSEEN_HEIGHTS / span)).astype(np.int64), UNSEEN_HEIGHTS - 1)
    return band * UNSEEN_AZIMUTHS + sector


def unseen_map(bins: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """The map (float32, `UNSEEN_MAP_SIZE`) for the samples' `bins` (`sample_bins`) and which of them the
    episode has `seen`: each bin's unseen samples over the samples an average bin holds."""
    if bins.shape != seen.shape:
        raise ValueError(f"bins {bins.shape} and seen {seen.shape} must have one entry per surface sample")
    counts = np.bincount(bins[~seen], minlength=UNSEEN_MAP_SIZE)
    return (counts * (UNSEEN_MAP_SIZE / max(len(bins), 1))).astype(np.float32)
