"""`nbv tables`: the Sec. VII arithmetic by hand, and `--quick` end to end with every part and its index."""

import json
import subprocess
import sys

import pytest
from PIL import Image

from common.provenance import git_commit
from nbv.experiments.paper import PaperConfig, sec7_summary, write_index


def test_sec7_is_views_saved_and_error_change_against_the_full_scan():
    rows = [{"scene": "a", "ranges": "-", "views": 288, "gt_chamfer_cm": 0.5, "gt_hausdorff_cm": 5.0},
            {"scene": "a", "ranges": 5, "views": 72, "gt_chamfer_cm": 0.4, "gt_hausdorff_cm": 6.0},
            {"scene": "a", "ranges": 7, "views": 144, "gt_chamfer_cm": 0.6, "gt_hausdorff_cm": 5.0},
            {"scene": "b", "ranges": "-", "views": 100, "gt_chamfer_cm": 1.0, "gt_hausdorff_cm": 2.0},
            {"scene": "b", "ranges": 5, "views": 50, "gt_chamfer_cm": 0.5, "gt_hausdorff_cm": 2.0}]
    summary = sec7_summary(rows)
    assert summary["a"] == {"fewer_views_pct": 62.5, "lower_chamfer_pct": 0.0, "lower_hausdorff_pct": -10.0}
    assert summary["b"] == {"fewer_views_pct": 50.0, "lower_chamfer_pct": 50.0, "lower_hausdorff_pct": 0.0}
    assert summary["mean"] == {"fewer_views_pct": 56.25, "lower_chamfer_pct": 25.0,
                               "lower_hausdorff_pct": -5.0}


def test_the_index_maps_every_result_present_and_keeps_each_parts_last_timing(tmp_path):
    (tmp_path / "table2.md").write_text("t")
    (tmp_path / "table2.json").write_text(json.dumps({"commit": "abc1234", "config": {"seeds": [0, 1]}}))
    round9 = tmp_path / "selection" / "round9"
    round9.mkdir(parents=True)
    (round9 / "README.md").write_text("r")
    (round9 / "results.json").write_text(json.dumps({"commit": "def5678", "seeds": [0, 1, 2]}))
    write_index(tmp_path, {"table2": 2294.4, "sec7": 1.0})
    index = write_index(tmp_path, {"episodes": 728.0}).read_text()  # a later run of one part
    commit = git_commit()
    assert f"table2 2294 s (at {commit}), sec7 1 s (at {commit}), episodes 728 s (at {commit})" in index
    row = ("| `table2.md` | Table 2 (views kept, Hausdorff, Chamfer per N and W) | `make tables` | 0, 1 "
           "| abc1234 |")
    assert row in index
    assert "| `selection/round9/README.md` | its ninth round: students without frames |" in index
    assert "`fig1_fig7.md`" not in index  # absent results are not listed


def test_tables_need_a_policy():
    with pytest.raises(ValueError, match="at least one policy"):
        PaperConfig(policies=())


def test_parts_run_in_order_whatever_the_flags_say():
    assert PaperConfig(part=("budget", "table2")).parts == ("table2", "budget")
    assert PaperConfig().parts == ("table2", "sec7", "episodes", "budget")


@pytest.mark.slow
def test_tables_quick_writes_every_part_and_the_index(tmp_path):
    # 4 spp instead of 16: every part and planner still runs, on a quarter of the rendering
    run = subprocess.run([sys.executable, "-m", "nbv.cli", "tables", "--quick", "--out", str(tmp_path),
                          "--spp", "4"], capture_output=True, text=True, timeout=540)
    assert run.returncode == 0, run.stderr[-3000:]
    for name in ("table2.md", "table2.png", "sec7.md", "fig1_fig7.md", "fig1_fig7.png", "budget/budget.md",
                 "budget/budget.png", "README.md"):
        assert (tmp_path / name).is_file(), name
    assert "paper Sec. VII | 70.6" in (tmp_path / "sec7.md").read_text()
    episodes = (tmp_path / "fig1_fig7.md").read_text()
    assert "test_building: Fig. 1 (trained on), ours (policy-shipped)" in episodes
    assert "test_building: Fig. 1 (trained on), ours (policy-paper)" in episodes  # the paper's method beside
    assert "paper Fig. 1 | 13 | 94.60 | 2.78" in episodes
    budget = json.loads((tmp_path / "budget" / "budget.json").read_text())
    rows = {r["planner"]: r for r in budget["rows"]["coverage"] if r["scene"] == "test_building"}
    assert set(rows) == {"random", "circle", "orbit", "orbit2", "greedy", "infogain", "lookahead-stereo",
                         "policy-shipped", "policy-paper", "oracle"}
    for planner, row in rows.items():  # the oracle bounds the reported coverage at every budget (one seed)
        assert all(o >= m for o, m in zip(rows["oracle"]["mean"], row["mean"])), planner
    index = (tmp_path / "README.md").read_text()
    assert all(f"`{name}`" in index for name in ("table2.md", "sec7.md", "fig1_fig7.md", "budget/budget.md"))
    with Image.open(tmp_path / "fig1_fig7.png") as image:
        assert image.size[0] > 500
