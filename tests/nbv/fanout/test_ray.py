"""Units on a local Ray instance (2 CPUs): the same comparison as in process, a killed worker retried."""

from __future__ import annotations

import json

import dying_units
import pytest
from ray import cloudpickle

from nbv.cli import main
from nbv.fanout import ExecutorConfig, Task, WorkerDied, run_tasks
from scenes import load_scene

RAY = ExecutorConfig(workers=2, ray="auto")


def test_a_comparison_on_ray_gives_the_numbers_of_one_in_process(tmp_path, capsys):
    reference = tmp_path / "reference.ply"
    load_scene("test_building").target_mesh().export(reference)
    args = ["compare", "test_building", "--planners", "random", "circle", "--seeds", "0", "1", "--views", "3",
            "--width", "64", "--height", "48", "--spp", "1", "--reference", str(reference),
            "--metric-points", "3000", "--voxel-size-m", "0.01"]
    assert main([*args, "--out", str(tmp_path / "here")]) == 0
    assert main([*args, "--out", str(tmp_path / "ray"), "--ray", "auto", "--workers", "2"]) == 0
    capsys.readouterr()
    here, ray = (json.loads((tmp_path / out / "comparison.json").read_text()) for out in ("here", "ray"))
    assert len(ray["runs"]) == 4 and {**here["config"], "out": ""} == {**ray["config"], "out": ""}
    for mine, theirs in zip(here["runs"], ray["runs"], strict=True):
        assert {k: mine[k] for k in ("planner", "seed", "views", "gt", "reference")} == \
            {k: theirs[k] for k in ("planner", "seed", "views", "gt", "reference")}
    here, there = (tmp_path / out / "comparison.md" for out in ("here", "ray"))
    assert here.read_text() == there.read_text()
    for run in ("random-seed1", "circle-seed0"):
        plans = [json.loads((tmp_path / out / run / "plan.json").read_text()) for out in ("here", "ray")]
        assert plans[0]["viewpoints"] == plans[1]["viewpoints"] and plans[0]["gt"] == plans[1]["gt"]


def test_a_ray_worker_killed_mid_unit_is_retried_and_one_that_always_dies_is_named(tmp_path):
    cloudpickle.register_pickle_by_value(dying_units)  # Ray workers do not have tests/ on their path
    try:
        dies = Task("dies once", dying_units.die_once,
                    {"out": tmp_path / "once", "marker": tmp_path / "marker"},
                    tmp_path / "once" / "result.txt")
        assert run_tasks([dies], RAY) == [dies]
        assert (tmp_path / "once" / "result.txt").read_text() == "second try"
        doomed = Task("doomed", dying_units.always_die, {"out": tmp_path / "doomed"},
                      tmp_path / "doomed" / "result.txt")
        with pytest.raises(WorkerDied, match="task 'doomed': its Ray worker died 2 times"):
            run_tasks([doomed], RAY)
    finally:
        cloudpickle.unregister_pickle_by_value(dying_units)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["marker", "once"]  # nothing partial of either
