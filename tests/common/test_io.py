"""Dead runs' leftovers: a folder written by a process that died is removed, a live one's is kept."""

from __future__ import annotations

import os
import subprocess
import time

from common.io import recover_stale


def test_a_dead_writers_temporary_folder_is_removed_even_before_it_is_reaped(tmp_path):
    child = subprocess.Popen(["true"])  # never waited for while we look: a zombie once it exits
    while open(f"/proc/{child.pid}/stat").read().rsplit(")", 1)[1].split()[0] != "Z":
        time.sleep(0.01)
    zombie = tmp_path / f".out.tmp-{child.pid}-abc"
    live = tmp_path / f".out.tmp-{os.getpid()}-def"
    for folder in (zombie, live):
        folder.mkdir()
        (folder / "half.txt").write_text("half")
    recover_stale(tmp_path / "out")
    child.wait()
    assert sorted(p.name for p in tmp_path.iterdir()) == [live.name]
