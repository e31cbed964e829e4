"""`nbv bench --area threads`: the rows of a quick run, and the busy process never outliving its block."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from synthetic import textured

from nbv.bench import AREAS, threads


def test_busy_process_is_terminated_even_when_the_block_fails():
    with pytest.raises(RuntimeError), threads.busy_process() as proc:
        assert proc.poll() is None  # spinning
        raise RuntimeError("boom")
    assert proc.poll() is not None


def test_sift_per_view_runs_at_the_asked_threads_and_restores_them(monkeypatch):
    seen = []
    real = threads.extract_features
    monkeypatch.setattr(threads, "extract_features",
                        lambda images, config: seen.append(torch.get_num_threads()) or real(images, config))
    before = torch.get_num_threads()
    ms = threads.per_view_ms(np.stack([textured(48, 64, 0)]), threads.FeatureConfig(), 1, 1)
    assert ms > 0 and seen == [1, 1] and torch.get_num_threads() == before


def test_quick_run_reports_sift_idle_and_busy_and_the_planning_step(monkeypatch):
    # Synthetic views instead of renders, and SIFT timings stubbed (Kornia on all cores takes seconds per
    # view on loaded cores); the planning step runs for real on two 160x120 views.
    images = np.stack([textured(120, 160, s) for s in range(2)])
    monkeypatch.setattr(threads, "render_views", lambda w, h, n: (images[:n], None, None))
    monkeypatch.setattr(threads, "per_view_ms", lambda imgs, config, n, repeats: {"kornia": 20.0 * n}.get(
        config.backend, 5.0))
    monkeypatch.setattr(threads.os, "sched_getaffinity", lambda pid: {0, 1})
    assert "threads" in AREAS and AREAS.index("threads") < AREAS.index("rl")
    rows = {r.name: r for r in threads.run(True)}
    assert all(r.area == "threads" for r in rows.values())
    for load in ("idle", "busy"):
        assert rows[f"SIFT Kornia 160x120, 1 torch thread (policy), {load}"].value == 20.0
        assert rows[f"SIFT Kornia 160x120, 2 torch threads (all cores), {load}"].value == 40.0
        assert rows[f"SIFT OpenCV 160x120, {load}"].unit == "ms/view"
        assert rows[f"SIFT Kornia (1 thread) / OpenCV 160x120, {load}"].value == pytest.approx(4.0)
        assert rows[f"SIFT Kornia 2 threads / 1 thread 160x120, {load}"].value == pytest.approx(2.0)
    label = "planning step 160x120 (kornia SIFT + BoV reward + policy, no render, 1 torch thread)"
    idle, busy = rows[f"{label}, idle"], rows[f"{label}, busy"]
    assert idle.unit == busy.unit == "ms" and idle.value > 0 and busy.value > 0
    assert idle.goal.startswith("<= 50: ") and busy.goal.startswith("<= 100: ")
    assert rows["planning step busy / idle"].value == pytest.approx(busy.value / idle.value)
    stages = sum(rows[f"planning step {s}, idle"].value for s in ("features", "bov", "policy"))
    assert stages == pytest.approx(idle.value)
    assert not any("320x240" in name for name in rows)  # quick: one resolution
