"""`scripts/teacher_eval.py` end to end on hand-made runs (its flights replaced): the teacher's name says its
flight terms, and its table and record count the acceptance checks as `looks_eval.py` does."""

from __future__ import annotations

import json
import sys

from scripts import looks_eval, teacher_eval
from tests.scripts.test_looks_eval import results


def test_the_teachers_checks_are_counted_and_recorded(tmp_path, monkeypatch):
    made = results()
    made["orbit2"] = made["orbit"]
    for by_building in made["pol"]["runs"].values():
        by_building["blank"] = {}  # a teacher flies no blank images

    def fly(planners, trained, scenes, seeds, views, work):
        runs = {name: made["pol" if name.startswith("teacher") else name] for name in planners}
        for doc in runs.values():
            doc["summary"] = looks_eval.summarise(doc["runs"], scenes, seeds)
        return runs

    monkeypatch.setattr(teacher_eval, "evaluate", fly)
    argv = ["teacher_eval.py", "--flight-reward", "0.2", "--flight-allowance", "11", "--flight-excess-reward",
            "1", "--scenes", "a", "b", "--seeds", "0", "1", "--out", str(tmp_path / "out"),
            "--work", str(tmp_path)]
    monkeypatch.setattr(sys, "argv", argv)
    monkeypatch.setattr(teacher_eval, "refuse_held_out", lambda scenes: None)
    teacher_eval.main()
    name = "teacher_h3_d0.9_w0.2_a11x1"
    record = json.loads((tmp_path / "out" / "results.json").read_text())
    assert list(record["checks"]) == [name]
    # No blank flights for a teacher: five of the hand-made policy's checks, the blank one unmeasured.
    table = (tmp_path / "out" / "results.md").read_text()
    assert f"| {name} | 93.0 | +2.8 | -0.5 | 13.0 | 0.50 | - | 4/6 |" in table
