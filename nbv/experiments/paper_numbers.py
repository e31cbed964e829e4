"""The numbers the paper reports, transcribed once, for side-by-side tables.

Source: S. Hatami Gazani, M. Tucsok, I. Mantegh and H. Najjaran, "Bag of Views: An
Appearance-based Approach to Next-Best-View Planning for 3D Reconstruction", IEEE RA-L,
2023. These are the paper's figures, never ours: tables label them "paper".
"""

from __future__ import annotations

TABLE2_RANGES = (5, 5, 5, 7, 7, 7, 9, 9, 9, 11, 11, 11)
"""Table 2 columns: size of the BoV (number of azimuth ranges N)."""
TABLE2_WORDS = (10, 20, 30) * 4
"""Table 2 columns: number of words per view range W."""

TABLE2 = {
    "medieval_tavern": {
        "views": (143, 67, 37, 142, 63, 34, 140, 62, 35, 146, 63, 42),
        "hausdorff_cm": (2.1509, 1.8134, 1.8901, 1.8045, 2.3907, 2.2756,
                         1.8803, 2.3693, 1.5216, 1.4825, 1.7841, 1.4355),
        "chamfer_cm": (0.1183, 0.1935, 0.4542, 0.1206, 0.4345, 0.3742,
                       0.1254, 0.1906, 0.2998, 0.1109, 0.1953, 0.2979),
    },
    "forest_ruin_house": {
        "views": (102, 38, 23, 92, 33, 24, 98, 42, 32, 99, 47, 36),
        "hausdorff_cm": (2.5810, 2.2692, 2.5231, 2.0577, 2.1886, 3.1446,
                         2.1244, 2.2862, 2.3698, 2.04848, 2.6412, 1.7054),
        "chamfer_cm": (0.2374, 0.4554, 0.6548, 0.2416, 0.5375, 0.5775,
                       0.1869, 0.6057, 0.5842, 0.3115, 0.5359, 0.5535),
    },
}
"""Table 2: views kept of 288, and Hausdorff / Chamfer (cm) against the 288-view reconstruction."""

FULL_SCAN_VIEWS = 288
"""Views of the full-coverage hemisphere scan every result is compared with."""

FIG1_NBV = {"views": 13, "coverage": 0.946, "hausdorff_cm": 2.78, "chamfer_cm": 0.80}
"""Fig. 1: the SAC policy's reconstruction against the 288-view scan."""

FIG7_GENERALISATION = {
    "alpine_chalet": {"hausdorff_cm": 9.47, "chamfer_cm": 1.01},
    "imperial_temple": {"hausdorff_cm": 6.35, "chamfer_cm": 0.82},
}
"""Fig. 7: the policy trained on one building, evaluated on two unseen ones."""

PLANNING_SECONDS_PER_STEP = 0.893
"""Sec. VI-C: average planning time per step on an NVIDIA RTX 3060."""

TABLE1_HYPERPARAMETERS = {"batch_size": 8, "lr": 5e-4, "alpha": 0.2, "target_update_interval": 20,
                          "buffer_size": 1_000_000, "tau": 0.01, "gamma": 0.99}
"""Table 1: SAC hyper-parameters."""

SEC7_SUMMARY = {"fewer_views_pct": 70.6, "lower_error_pct": 33.5}
"""Sec. VII: Bag of Views refinement against the full-coverage scan, 70.6 % fewer views and 33.5 % lower
reconstruction error."""
