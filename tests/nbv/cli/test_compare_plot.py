"""`nbv plot-training` and `nbv compare` run end to end as a user runs them (tiny inputs, no rendering)."""

from __future__ import annotations

import json
import subprocess
import sys

from PIL import Image

from nbv.flight import flight_record
from render.viewpoint import Viewpoint

FLIGHT = {"viewpoints": [[2.0, 1.0, 0.5]],
          **flight_record(Viewpoint(2.0, 0.0, 0.5), [Viewpoint(2.0, 1.0, 0.5)])}
"""A one-view flight record, as plan.json holds it (compare reads it)."""


def run_nbv(*args: str) -> subprocess.CompletedProcess:
    """`nbv ARGS` in a fresh process, as a user runs it."""
    return subprocess.run([sys.executable, "-m", "nbv.cli", *args], capture_output=True, text=True,
                          check=False)


def test_plot_training_overlays_runs(tmp_path):
    for name in ("a", "b"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "metrics.csv").write_text(
            "frames,updates,reward_mean,episode_return,episodes\n10,0,1.0,,0\n20,10,2.0,5.0,1\n")
    done = run_nbv("plot-training", f"first={tmp_path / 'a'}", str(tmp_path / "b"),
                   "--out", str(tmp_path / "curves.png"))
    assert done.returncode == 0, done.stderr
    assert Image.open(tmp_path / "curves.png").size[0] > 500
    missing = run_nbv("plot-training", str(tmp_path / "nothing"), "--out", str(tmp_path / "x.png"))
    assert missing.returncode == 2 and "an `nbv train` run folder?" in missing.stderr


def test_compare_planners_reads_back_finished_runs(tmp_path):
    metrics = {"coverage": 0.5, "chamfer_cm": 1.0, "hausdorff_cm": 5.0}
    for seed in (0, 1):
        (tmp_path / f"circle-seed{seed}").mkdir()
        (tmp_path / f"circle-seed{seed}" / "plan.json").write_text(
            json.dumps({"views": 13, "gt": metrics, "reference": metrics, "planning_s": 0.0,
                        "deciding_s": 0.0, **FLIGHT}))
    done = run_nbv("compare", "alpine_chalet", "--planners", "circle", "--seeds", "0", "1",
                   "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    assert "| circle (2 seeds) | 13.0 ± 0.0 | 50.00 ± 0.00 |" in done.stdout
    assert json.loads((tmp_path / "comparison.json").read_text())["planners"] == ["circle"]
