"""`scripts/capacity_plan.py` end to end on tiny measured inputs: unit counts from the ablation axes."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_plan_counts_the_ablation_units_from_the_axes_and_writes_the_page(tmp_path):
    runs = [{"planning_s": 1.0}, {"planning_s": 3.0}]
    online = {"budget": {"a": {"random": runs}, "b": {"random": runs}}, "one_pass": {"a": {"random": runs}}}
    (tmp_path / "online.json").write_text(json.dumps(online))
    (tmp_path / "table2.json").write_text(json.dumps({"config": {"scenes": ["a", "b"]}, "seconds": 100.0}))
    results = [{"area": "fanout", "name": "1-minute load average at the start (cores busy before the bench)",
                "value": 0.2, "unit": "", "goal": ""},
               {"area": "fanout", "name": "speed-up, 2 local workers, over in process", "value": 1.8,
                "unit": "x", "goal": ""}]
    (tmp_path / "bench.json").write_text(json.dumps({"machine": "m", "commit": "c", "time": "t",
                                                     "results": results}))
    out = tmp_path / "capacity.md"
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "capacity_plan.py"), "--online",
                           str(tmp_path / "online.json"), "--table2", str(tmp_path / "table2.json"),
                           "--bench", str(tmp_path / "bench.json"), "--reference-s", "10",
                           "--ablation-s", "1", "--ablation-lighting-s", "2", "--startup-s", "0",
                           "--out", str(out)],
                          cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    page = out.read_text()
    # nbv ablate's default run: 2 buildings x 3 seeds x (the reference + 28 levels), 6 of 29 greedy:
    # 36 x 2 s + 138 x 1 s = 210 core seconds.
    assert f"| ablations | 174 | {210 / 3600:.1f} | 2 |" in page
    # 2 references of 10 s, then 6 plan runs of 31 s fixed + 1 or 3 s planning.
    assert "| planner comparison (nbv online) | 8 |" in page
    assert "an efficiency of 0.90 to 1.00 per core" in page
