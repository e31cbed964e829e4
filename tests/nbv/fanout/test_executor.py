"""`run_tasks` in process and on local workers: skips, repeats, named errors, a worker killed mid-unit, warm
workers kept for the process."""

from __future__ import annotations

import os

import pytest
from dying_units import always_die, die_once, write_pid_and_env, write_result

from nbv.fanout import ExecutorConfig, Task, WorkerDied, run_tasks, start_workers
from nbv.fanout.processes import start_pool
from nbv.fanout.worker import cap_threads, core_share


def entries(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_units_run_once_and_done_units_are_skipped(tmp_path):
    a = Task("a", write_result, {"out": tmp_path / "a", "text": "A"}, tmp_path / "a" / "result.txt")
    b = Task("b", write_result, {"out": tmp_path / "b", "text": "B"}, tmp_path / "b" / "result.txt")
    finished = []
    assert run_tasks([a, b, a], on_done=lambda task: finished.append(task.name)) == [a, b]
    assert finished == ["a", "b"] and (tmp_path / "b" / "result.txt").read_text() == "B"
    assert run_tasks([a, b]) == []


def test_a_units_error_names_it_and_names_are_unique(tmp_path):
    bad = Task("bad unit", write_result, {"out": tmp_path / "x"}, tmp_path / "x" / "result.txt")
    with pytest.raises(TypeError) as info:
        run_tasks([bad])
    assert "in task 'bad unit'" in info.value.__notes__
    other = Task("bad unit", write_result, {"out": tmp_path / "y", "text": ""})
    with pytest.raises(ValueError, match="two different tasks are both named 'bad unit'"):
        run_tasks([bad, other])


def test_bad_executor_settings_are_refused():
    with pytest.raises(ValueError, match="workers must be >= 1"):
        ExecutorConfig(workers=0)
    with pytest.raises(ValueError, match="'auto' or a cluster address"):
        ExecutorConfig(ray=" ")


def test_a_worker_caps_drjit_and_torch_to_its_share():
    assert core_share(2, cores=16) == 8 and core_share(3, cores=2) == 1
    import drjit as dr
    import torch

    before = dr.thread_count(), torch.get_num_threads()
    try:
        assert cap_threads(1) == (1, 1)
        assert (dr.thread_count(), torch.get_num_threads()) == (1, 1)
    finally:
        dr.set_thread_count(before[0])
        torch.set_num_threads(before[1])


def test_a_worker_killed_mid_unit_is_retried_and_one_that_always_dies_is_named(tmp_path):
    workers = ExecutorConfig(workers=2)
    dies = Task("dies once", die_once, {"out": tmp_path / "once", "marker": tmp_path / "marker"},
                tmp_path / "once" / "result.txt")
    fine = Task("fine", write_result, {"out": tmp_path / "fine", "text": "fine"},
                tmp_path / "fine" / "result.txt")
    assert run_tasks([dies, fine], workers) == [dies, fine]
    assert (tmp_path / "once" / "result.txt").read_text() == "second try"
    assert (tmp_path / "fine" / "result.txt").read_text() == "fine"
    assert entries(tmp_path) == ["fine", "marker", "once"]  # no temporary folder of the killed worker
    doomed = Task("doomed", always_die, {"out": tmp_path / "doomed"}, tmp_path / "doomed" / "result.txt")
    with pytest.raises(WorkerDied, match="task 'doomed': its worker process died twice"):
        run_tasks([doomed], workers)
    assert entries(tmp_path) == ["fine", "marker", "once"]


def test_workers_live_for_the_process_and_take_the_callers_nbv_environment(tmp_path, monkeypatch):
    workers = ExecutorConfig(workers=2)
    start_workers(workers)

    def unit(name: str) -> Task:
        return Task(name, write_pid_and_env, {"out": tmp_path / name, "name": "NBV_PROBE"},
                    tmp_path / name / "result.txt")

    def seen(name: str) -> tuple[int, str]:
        pid, value = (tmp_path / name / "result.txt").read_text().split()
        return int(pid), value

    monkeypatch.setenv("NBV_PROBE", "first")
    run_tasks([unit("a"), unit("b")], workers)
    monkeypatch.setenv("NBV_PROBE", "second")  # set after the workers started
    run_tasks([unit("c"), unit("d")], workers)
    first, later = {seen("a"), seen("b")}, {seen("c"), seen("d")}
    assert {value for _, value in first} == {"first"} and {value for _, value in later} == {"second"}
    pids = {pid for pid, _ in first | later}
    assert os.getpid() not in pids and pids <= {p.pid for p in start_pool(2)._processes.values()}
