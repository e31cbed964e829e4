"""The missed-voxels diagnostic's count on a hand-made grid: each state, and an occupied voxel's side counted
as measured only from the quadrant its sample's face looks out to; the script's refusals."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from nbv.recon.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, sight_bin
from scripts import missed_voxels
from scripts.missed_voxels import voxel_states


def test_states_and_the_occupied_measured_from_the_faces_quadrant():
    grid = OccupancyGrid(np.zeros(3), np.array([4.0, 1.0, 1.0]), resolution=4)
    grid.state[:, 0, 0] = [UNKNOWN, FREE, OCCUPIED, OCCUPIED]
    toward, away = sight_bin(np.array([-1.0, 0, 0])), sight_bin(np.array([1.0, 0, 0]))
    grid.sides[2], grid.sides[3] = 1 << toward, 1 << away  # voxel 2 met by a ray going -x, voxel 3 by +x
    samples = np.array([[0.5, 0.5, 0.5], [1.5, 0.5, 0.5], [2.5, 0.5, 0.5], [3.5, 0.5, 0.5]])
    normals = np.tile([1.0, 0, 0], (4, 1))  # every face looks out to +x: seen by rays going -x
    assert voxel_states(grid, samples, normals) == {"unknown": 1, "free": 1, "occupied": 2,
                                                    "occupied, its quadrant measured": 1}
    steep = OccupancyGrid(np.zeros(3), np.array([4.0, 1.0, 1.0]), resolution=4, steep_deg=60)
    steep.state[:, 0, 0] = OCCUPIED
    steep.sides[0] = 1 << int(sight_bin(np.array([-0.3, 0, -0.95]), 60))  # steeply down, going -x
    steep.sides[1] = 1 << int(sight_bin(np.array([-0.8, 0, -0.6]), 60))  # down, not steeply
    counted = voxel_states(steep, samples[:2], normals[:2])["occupied, its quadrant measured"]
    assert counted == 1  # the steep band measures no side


def test_the_script_refuses_held_out_buildings_and_flights_it_does_not_have(tmp_path):
    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, missed_voxels.__file__, *args], capture_output=True, text=True,
                              check=False)

    refused = run("--work", str(tmp_path), "--scene", "imperial_temple", "--planner", "p", "--out", "x")
    assert "held-out buildings are not for choosing: imperial_temple" in refused.stderr
    missing = run("--work", str(tmp_path), "--scene", "family:9", "--planner", "p", "--out", "x")
    assert "no flights of p on family:9" in missing.stderr
