"""`scripts/fit_curves.py` on hand-made fit records: each curve's first, best and last value, the ranking
rounds read one after another, a picture, and a malformed argument refused by its message."""

from __future__ import annotations

import json

import pytest
from PIL import Image

from scripts import fit_curves


def test_the_curves_best_values_and_passes_are_tabled_and_drawn(tmp_path):
    seed_fit = {"iteration": "buffers", "passes": [{"held": 1.5}, {"held": 0.8}, {"held": 0.9}]}
    dagger = {"iterations": [seed_fit, {"iteration": 0, "passes": [{"held": 0.1}]}]}  # later: not drawn
    ranking = {"rounds": [{"passes": [{"held_regret": 2.0}, {"held_regret": 1.0}]},
                          {"passes": [{"held_regret": 0.4}, {"held_regret": 0.5}]}]}
    (tmp_path / "d.json").write_text(json.dumps(dagger))
    (tmp_path / "r.json").write_text(json.dumps(ranking))
    assert fit_curves.dagger_curve(dagger) == [1.5, 0.8, 0.9]
    assert fit_curves.ranking_curve(ranking) == [2.0, 1.0, 0.4, 0.5]
    out = tmp_path / "out"
    fit_curves.main(["--dagger", f"map={tmp_path / 'd.json'}", "--ranking", f"rank={tmp_path / 'r.json'}",
                     "--out", str(out)])
    table = (out / "fit_curves.md").read_text()
    assert "| imitation fit | map | 1.50 | 0.80 (2) | 0.90 |" in table
    assert "| ranking student | rank | 2.00 | 0.40 (3) | 0.50 |" in table
    assert Image.open(out / "fit_curves.png").size[0] > 1000  # two panels side by side


def test_an_argument_without_a_path_is_refused(tmp_path):
    with pytest.raises(SystemExit, match="expected NAME=PATH"):
        fit_curves.main(["--dagger", "map", "--out", str(tmp_path)])
