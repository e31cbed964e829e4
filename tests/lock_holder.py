"""A test helper: another process holding an output's lock, as a run writing it does."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def hold(out: Path, seconds: float = 60.0) -> subprocess.Popen:
    """Another process holding the lock of `out` for `seconds` (it has it once this returns)."""
    code = (f"import time; from common.locks import claim; claim({str(out)!r}); print('held', flush=True); "
            f"time.sleep({seconds})")
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                             env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert child.stdout.readline().strip() == "held"
    return child
