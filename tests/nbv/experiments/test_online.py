"""`nbv online`: runs on disk are read back; margins, speed-up and the one-pass table by hand."""

from __future__ import annotations

import json

import pytest
from PIL import Image

from nbv.cli import main
from nbv.experiments.online import OnlineConfig, run_online, scene_folder


def metrics(coverage: float, chamfer: float = 0.5, hausdorff: float = 5.0) -> dict:
    return {"coverage": coverage, "chamfer_cm": chamfer, "hausdorff_cm": hausdorff}


def save_run(folder, views: int, coverage: float, planning_s: float, legs: tuple[float, ...] = (2.0, 2.0),
             azimuths: tuple[float, ...] = (1.0, 2.0)) -> None:
    folder.mkdir(parents=True)
    flight = {"start_viewpoint": [2.0, 0.0, 0.5], "viewpoints": [[2.0, a, 0.5] for a in azimuths],
              "legs_m": list(legs), "flight_m": sum(legs), "azimuth_reversals": 0}
    (folder / "plan.json").write_text(json.dumps({
        "views": views, "gt": metrics(coverage), "reference": metrics(coverage + 0.05, 0.8, 3.0),
        "planning_s": planning_s + 1.0, "deciding_s": planning_s,  # 1 s rendering the views flown to
        **flight}))


def test_online_report_from_saved_runs(tmp_path):
    # Two buildings, two seeds: the policy covers 80/90 %, another seed's 70/80, the depth option 90, random
    # 70, circle 60, greedy 85 (gt).
    coverage = {"policy-shipped": (0.8, 0.9), "policy-seed1": (0.7, 0.8), "lookahead": (0.9, 0.9),
                "random": (0.7, 0.7), "circle": (0.6, 0.6), "greedy": (0.85, 0.85)}
    planning = {"policy-shipped": 0.5, "policy-seed1": 0.5, "lookahead": 2.0, "random": 0.0, "circle": 0.0,
                "greedy": 50.0}
    for scene in ("alpine_chalet", "random:5"):
        root = tmp_path / scene_folder(scene)
        for label, values in coverage.items():
            for seed in (0, 1):
                turns = (1.0, 0.5) if label == "random" and seed == 1 else (1.0, 2.0)  # one turn back
                save_run(root / "views13" / f"{label}-seed{seed}", 13, values[seed], planning[label],
                         (2.0, 2.0 + seed + (scene == "random:5")), turns)
        for seed in (0, 1):  # every policy flies one pass: the second (the paper's, say) two views more
            save_run(root / "onepass" / f"policy-shipped-seed{seed}", 10 + seed, 0.75, 0.4)
            save_run(root / "onepass" / f"policy-seed1-seed{seed}", 12 + seed, 0.65, 0.4)
            for label in ("policy-shipped", "policy-seed1"):  # blind, the shipped one covers 15 points less
                save_run(root / "views13-blank" / f"{label}-seed{seed}", 13, 0.7, 0.5)
    config = OnlineConfig(out=tmp_path, scenes=("alpine_chalet", "random:5"), seeds=(0, 1),
                          policies=("policy", f"policy:{tmp_path / 'seed1' / 'policy.pt'}"),
                          baselines=("random", "circle", "greedy"))
    text = run_online(config)
    assert "| **mean** | **85.0** | **75.0** | **90.0** | **70.0** | **60.0** | **85.0** |" in text
    assert "- policy-shipped minus random: +15.0 points" in text
    assert "- policy-shipped minus lookahead: -5.0 points" in text
    assert "lookahead (the depth option) reads the depth it measures" in text
    assert "- policy-shipped minus greedy: +0.0 points" in text
    assert ("Re-run: `nbv online --scenes alpine_chalet random:5 --policies policy "
            "policy:ELSEWHERE/seed1/policy.pt --depth-options lookahead --baselines random circle greedy "
            "--seeds 0 1 --views 13 --out DIR`") in text  # no machine's folders in a committed report
    assert "- planning speed-up over greedy (without the simulated camera): 100x" in text
    spread = ("- spread over the 2 policies: 10.0 points "
              "(policy-shipped 85.0, policy-seed1 75.0)")
    assert spread in text
    assert "policy-shipped 1.50 / 0.50" in text
    row = next(line for line in text.splitlines() if line.startswith("| random:5 (policy-shipped)"))
    assert row == "| random:5 (policy-shipped) | 10.5 | 80.0 | 3.00 | 0.80 | 75.0 | 4.0 |"
    row = next(line for line in text.splitlines() if line.startswith("| random:5 (policy-seed1)"))
    assert row == "| random:5 (policy-seed1) | 12.5 | 70.0 | 3.00 | 0.80 | 65.0 | 4.0 |"
    assert "| random:5 | 5.5 / 0.0 | 5.5 / 0.0 | 5.5 / 0.0 | 5.5 / 0.5 | 5.5 / 0.0 | 5.5 / 0.0 |" in text
    assert "| **mean** | **5.0 / 0.0** | **5.0 / 0.0** | **5.0 / 0.0** | **5.0 / 0.5** | **5.0 / 0.0** |" in (
        text)
    assert "| paper Fig. 7 (alpine_chalet) | - | - | 9.47 | 1.01 | - |" in text
    assert "## Acceptance (issue 26): each policy against the tuned orbit on 2 buildings" in text
    assert "| check | bar | policy-shipped | policy-seed1 | lookahead (depth) |" in text
    assert ("| coverage lost with blank images, points | >= 3.0 | +15.0 (yes) | +5.0 (yes) | does not apply "
            "(reads no image) |") in text
    no_orbit = "| mean coverage minus the tuned orbit's, points | >= +3.0 | n/a (no) | n/a (no) | n/a (no) |"
    assert no_orbit in text
    spread = "| path spread, closest pair of buildings, m | >= 0.20 | 0.00 (no) | 0.00 (no) | 0.00 (no) |"
    assert spread in text
    assert (tmp_path / "online.md").read_text() == text
    saved = json.loads((tmp_path / "online.json").read_text())
    assert saved["config"]["seeds"] == [0, 1] and len(saved["budget"]["random:5"]["greedy"]) == 2
    assert str(tmp_path) not in json.dumps(saved)
    assert saved["config"]["out"] == f"ELSEWHERE/{tmp_path.parent.name}/{tmp_path.name}"
    assert len(saved["blank"]["random:5"]["policy-seed1"]) == 2 and set(saved["acceptance"]) == {
        "policy-shipped", "policy-seed1", "lookahead"}
    assert Image.open(tmp_path / "online.png").size[0] > 300
    assert scene_folder("random:5") == "random_5"


def test_online_needs_a_policy_and_a_seed(tmp_path, capsys):
    with pytest.raises(ValueError, match="at least one scene, one policy and one seed"):
        OnlineConfig(out=tmp_path, policies=())
    assert main(["online", "--out", str(tmp_path), "--views", "0"]) == 2
    assert "views must be >= 1" in capsys.readouterr().err


def test_online_hands_every_run_of_every_building_to_the_executor_at_once(tmp_path):
    from nbv.experiments.compare import comparison_tasks
    from nbv.experiments.online import comparisons
    from nbv.fanout.task import unique_tasks

    config = OnlineConfig(out=tmp_path, scenes=("alpine_chalet", "random:5"), seeds=(0, 1))
    stages = [comparison_tasks(comparison) for comparison in comparisons(config)]
    references = unique_tasks([task for refs, _ in stages for task in refs])
    runs = unique_tasks([task for _, plans in stages for task in plans])
    # one reference per building (both protocols share it); the two policies (the default's, the paper's),
    # the image-only look-ahead (lookahead-stereo), the depth option (lookahead) and the registry's 5
    # compared baselines (random, circle, orbit, orbit2, greedy) x 2 seeds at 13 views, + each learnt
    # policy's one pass (the look-ahead has no stop rule) + the three image readers' 13 views, images blank
    assert config.baselines == ("random", "circle", "orbit", "orbit2", "greedy")
    assert config.depth_options == ("lookahead",)
    assert [task.name for task in references] == ["full-scan reference of alpine_chalet",
                                                  "full-scan reference of random:5"]
    assert config.policies == ("policy", "policy-paper", "lookahead-stereo")
    assert len(runs) == 2 * (9 * 2 + 2 * 2 + 3 * 2)
    assert runs[-1].name == f"lookahead-stereo-seed1 in {tmp_path}/random_5/views13-blank"
    assert runs[-1].result == tmp_path / "random_5" / "views13-blank" / "lookahead-stereo-seed1" / "plan.json"
    one_pass = [c for c in comparisons(config) if c.views is None]
    assert [c.planners for c in one_pass] == [("policy", "policy-paper")] * 2
    blank = [c for c in comparisons(config) if c.settings.blank_images]
    assert [c.planners for c in blank] == [config.policies] * 2 and all(c.views == 13 for c in blank)
    assert len(comparisons(OnlineConfig(out=tmp_path, scenes=("random:5",), blank=False))) == 2
