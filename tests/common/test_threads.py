"""The thread policy: its values, the remembered per-process choice, the context manager, a light import."""

from __future__ import annotations

import subprocess
import sys

import pytest
import torch

from common import threads


@pytest.fixture
def fresh_process_state(monkeypatch):
    """No choice recorded yet, and torch's thread count put back afterwards."""
    before = torch.get_num_threads()
    monkeypatch.setattr(threads, "_chosen", None)
    yield
    torch.set_num_threads(before)


def test_policy_is_one_thread_unless_asked():
    assert threads.WORKER_THREADS == 1
    assert threads.worker_threads() == 1 and threads.worker_threads(0) == 1
    assert threads.worker_threads(-3) == 1
    assert threads.worker_threads(2) == 2 and threads.worker_threads(7) == 7


def test_apply_policy_sets_one_thread_when_nobody_chose(fresh_process_state):
    torch.set_num_threads(2)
    assert threads.chosen_threads() is None
    assert threads.apply_thread_policy() == 1 == torch.get_num_threads()
    assert threads.chosen_threads() == 1


def test_an_explicit_choice_is_kept(fresh_process_state):
    assert threads.set_torch_threads(2) == 2
    assert threads.apply_thread_policy() == 2 == torch.get_num_threads()


def test_zero_keeps_torch_default_and_counts_as_a_choice(fresh_process_state):
    torch.set_num_threads(2)
    assert threads.set_torch_threads(0) == 2
    assert threads.chosen_threads() == 0
    assert threads.apply_thread_policy() == 2


def test_negative_threads_rejected(fresh_process_state):
    with pytest.raises(ValueError, match="threads must be >= 0"):
        threads.set_torch_threads(-1)
    assert threads.chosen_threads() is None


def test_limit_restores_count_and_choice(fresh_process_state):
    torch.set_num_threads(2)
    with threads.limit_torch_threads(1) as inside:
        assert inside == 1 == torch.get_num_threads()
        assert threads.apply_thread_policy() == 1
    assert torch.get_num_threads() == 2 and threads.chosen_threads() is None
    with pytest.raises(RuntimeError), threads.limit_torch_threads(1):
        raise RuntimeError("boom")
    assert torch.get_num_threads() == 2


def test_importing_common_threads_does_not_import_torch():
    code = "import sys, common.threads; print('torch' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"
