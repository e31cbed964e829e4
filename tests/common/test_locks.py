"""One writer per output (issue 28): the lock beside an output, held by another process, refuses a second
writer at once naming the holder, waits when asked, and dies with a SIGKILLed holder."""

from __future__ import annotations

import os
import signal
import time

import pytest
from lock_holder import hold

from common.locks import OutputBusy, claim, lock_file, release


def test_second_writer_fails_at_once_naming_the_holders_pid_and_sigkill_frees_it(tmp_path):
    out = tmp_path / "run"
    holder = hold(out)
    try:
        start = time.monotonic()
        with pytest.raises(OutputBusy, match=rf"^{out} is being written by another run \(pid {holder.pid}\); "
                                             r".*--wait-for-lock"):
            claim(out)
        assert time.monotonic() - start < 1.0
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    claim(out)  # the kernel dropped the dead holder's lock
    assert lock_file(out).read_text().strip() == str(os.getpid())
    release(out)
    assert not lock_file(out).exists() and sorted(p.name for p in tmp_path.iterdir()) == []


def test_wait_for_lock_waits_until_the_holder_is_done(tmp_path):
    out = tmp_path / "run"
    holder = hold(out, seconds=0.5)
    start = time.monotonic()
    claim(out, wait=True)
    assert time.monotonic() - start >= 0.3  # the holder kept it 0.5 s
    release(out)
    holder.wait()


def test_claim_is_once_per_process_and_release_removes_the_lock_file(tmp_path):
    out = tmp_path / "run"
    claim(out)
    claim(tmp_path / "." / "run")  # the same output: already held, no second lock
    assert lock_file(out).is_file()
    release(out)
    release(out)
    assert not lock_file(out).exists()
