"""`nbv bench` end to end on its cheapest area: the figures, bench.json and bench.md."""

from __future__ import annotations

import json

from nbv.cli import main


def test_bench_quick_writes_json_and_markdown(tmp_path, capsys):
    assert main(["bench", "--quick", "--area", "cli", "--out", str(tmp_path)]) == 0
    doc = json.loads((tmp_path / "bench.json").read_text())
    assert doc["quick"] is True and doc["commit"]
    names = [r["name"] for r in doc["results"]]
    assert names == ["nbv --help start-up (fresh process)", "nbv scene list start-up (fresh process)"]
    assert all(r["area"] == "cli" and r["unit"] == "s" and r["value"] > 0 for r in doc["results"])
    table = (tmp_path / "bench.md").read_text()
    assert "| area | figure | value | unit | goal |" in table and "| cli | nbv scene list" in table
    printed = capsys.readouterr().out
    assert "[bench] cli done in" in printed and "| cli | nbv --help" in printed


def test_bench_rejects_an_unknown_area(tmp_path, capsys):
    assert main(["bench", "--area", "gpu", "--out", str(tmp_path)]) == 2
    assert "gpu" in capsys.readouterr().err and not (tmp_path / "bench.json").exists()


def test_bench_times_the_look_aheads_side_by_side(tmp_path):
    assert main(["bench", "--quick", "--area", "lookahead", "--out", str(tmp_path)]) == 0
    results = {r["name"]: r for r in json.loads((tmp_path / "bench.json").read_text())["results"]}
    seconds = [r["value"] for r in results.values() if r["unit"] == "s"]
    assert len(seconds) == 4 and all(s > 0 for s in seconds)
    three = results["stereo three frames / one frame"]["value"]
    assert three > 1.0  # two more renders and sweeps a view cost time
    assert results["lookahead-stereo (sides, route) / round 28's setting"]["value"] > 0

