"""The missed-surface diagnostic: how samples face, hand-worked; the script on two small flights; refusals."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

from scripts import missed_surface
from scripts.missed_surface import KINDS, describe, facing


def test_each_sample_faces_up_out_in_or_otherwise():
    points = np.array([[1.0, 0, 0.1]] * 4 + [[0, -2.0, 0.3]])
    normals = np.array([[0, 0, 1.0], [1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, -0.6, 0.8]])
    kinds = facing(points, normals, center=np.zeros(3))
    assert [KINDS[k] for k in kinds] == ["roof", "outer wall", "inner wall", "other", "roof"]
    tilted = facing(points[4:], np.array([[0, -0.8, 0.6]]), np.zeros(3))  # z 0.6: a wall, facing out
    assert KINDS[tilted[0]] == "outer wall"


def test_describe_counts_shares_and_medians():
    points = np.array([[3.0, 4.0, 1.0], [0.0, 1.0, 3.0], [9.0, 9.0, 9.0]])
    part = describe(np.array([True, True, False]), np.array([0, 2, 1]), points, np.zeros(3))
    assert part["count"] == 2 and part["kinds"] == {"roof": 0.5, "outer wall": 0.0, "inner wall": 0.5,
                                                    "other": 0.0}
    assert part["median_z_m"] == 2.0 and part["median_radius_m"] == 3.0  # radii 5 and 1
    assert describe(np.zeros(3, bool), np.zeros(3, int), points, np.zeros(3))["median_z_m"] is None


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, missed_surface.__file__, *args], capture_output=True, text=True,
                          check=False)


def test_the_script_compares_two_flights_and_refuses_held_out_or_missing_ones(tmp_path):
    low = [[1.5, a, np.radians(5)] for a in (0.0, 2.1, 4.2)]
    top = [[1.5, 0.0, np.radians(80)]]
    for name, views in (("low", low), ("top", top)):
        (tmp_path / name).mkdir()
        runs = {"0": {"viewpoints": views}}
        (tmp_path / name / "family_9.json").write_text(json.dumps({"result": {"runs": runs}}))
    done = run("--work", str(tmp_path), "--scene", "family:9", "--planner", "top", "--baseline", "low",
               "--seeds", "0", "--out", str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    row = json.loads((tmp_path / "out" / "results.json").read_text())["rows"][0]
    assert row["missed"]["count"] > 0 and row["alone"]["count"] > 0
    assert row["missed"]["kinds"]["outer wall"] > 0.5 and row["alone"]["kinds"]["roof"] > 0.5  # low: walls
    assert (tmp_path / "out" / "missed.png").stat().st_size > 0
    refused = run("--work", str(tmp_path), "--scene", "alpine_chalet", "--planner", "top", "--out", "x")
    assert "held-out buildings are not for choosing: alpine_chalet" in refused.stderr
    missing = run("--work", str(tmp_path), "--scene", "family:4", "--planner", "top", "--out", "x")
    assert "no flights of top on family:4" in missing.stderr


def test_the_script_reads_flights_from_studies_results_merging_their_start_views(tmp_path):
    low = [[1.5, a, np.radians(5)] for a in (0.0, 2.1, 4.2)]
    top = [[1.5, 0.0, np.radians(80)]]
    files = []
    for seed in (0, 1):
        study = {name: {"runs": {"family:9": {"runs": {str(seed): {"viewpoints": views}}}}}
                 for name, views in (("low", low), ("top", top))}
        files.append(tmp_path / f"study{seed}.json")
        files[-1].write_text(json.dumps({"results": study}))
    done = run("--results", *map(str, files), "--scene", "family:9", "--planner", "top", "--baseline", "low",
               "--seeds", "0", "1", "--out", str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    rows = json.loads((tmp_path / "out" / "results.json").read_text())["rows"]
    assert [r["seed"] for r in rows] == [0, 1] and all(r["missed"]["count"] > 0 for r in rows)
    missing = run("--results", str(files[0]), "--scene", "family:9", "--planner", "nobody", "--out", "x")
    assert "no flights of nobody on family:9 in" in missing.stderr
