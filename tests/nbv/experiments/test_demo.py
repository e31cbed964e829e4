"""`nbv demo` end to end on a small scan: every stage's files, a table, and scan reuse."""

import json

from nbv.bov.config import BoVConfig
from nbv.cli import main
from nbv.features.config import FeatureConfig
from nbv.rl.builders import make_loss_module, make_optimizers, make_replay_buffer, make_sac_agent
from nbv.rl.config import EnvConfig, LoggerConfig, OptimConfig, TrainConfig
from nbv.rl.train import write_checkpoint
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.spec import SceneSet


def untrained_policy(run) -> str:
    """A `policy.pt` of untrained networks on a tiny env (the demo's online half only needs its shape)."""
    env = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                    render=RenderSettings(spp=1),
                    bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")), obs_size=32,
                    max_steps=3)
    config = TrainConfig(env=env, logger=LoggerConfig(out=run))
    actor, critic = make_sac_agent(env, config.network)
    loss, _ = make_loss_module(actor, critic, OptimConfig())
    optim_actor, optim_critic = make_optimizers(loss, OptimConfig())
    run.mkdir()
    write_checkpoint(run / "checkpoint.pt", config, loss, optim_actor, optim_critic,
                     make_replay_buffer(config.replay_buffer), 0, 0, None)
    return f"policy:{run / 'policy.pt'}"


def test_demo_runs_every_stage_and_reuses_its_scan(tmp_path, capsys):
    out = tmp_path / "demo"
    args = ["demo", "--out", str(out), "--scene", "test_building", "--width", "96", "--height", "72",
            "--spp", "2", "--end-overlap", "0.5", "--side-overlap", "0.4", "--ranges", "3", "--words", "5",
            "--voxel-size-m", "0.01", "--metric-points", "5000", "--online-scene", "test_building",
            "--policy", untrained_policy(tmp_path / "run"), "--min-matches", "15"]
    tmp_path = out
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "| refined |" in printed and "Paper (Table 2" in printed
    assert "## Online half: test_building (held out)" in printed and "| random | " in printed
    assert "| orbit | " in printed and "| orbit2 | " in printed
    results = json.loads((tmp_path / "results.json").read_text())
    assert 0 < results["views_refined"] <= results["views_full"]
    for ref in ("gt", "reference"):
        assert 0 <= results["metrics"]["refined"][ref]["coverage"] <= 1
    full, refined = results["metrics"]["full"]["gt"], results["metrics"]["refined"]["gt"]
    assert full["coverage"] >= refined["coverage"] and full["chamfer_cm"] < 3.0  # 2 cm pixels at 96x72
    for name in ("contact_sheet", "trajectory_full", "trajectory_refined", "heatmap_refined_vs_full",
                 "heatmap_full_vs_gt"):
        assert (tmp_path / f"{results['figures'][name].split('/')[-1]}").stat().st_size > 0
    for sub in ("recon_full/mesh.ply", "recon_refined/points.ply", "refined/refine.json"):
        assert (tmp_path / sub).is_file()
    links = results["links"]  # --min-matches: the registrable refinement beside the paper's rule
    assert links["paper_kept"] == results["kept"] and links["min_matches"] == 15
    linked = json.loads((tmp_path / "refined_linked" / "refine.json").read_text())["kept"]
    assert sorted(set(results["kept"]) | set(links["added"])) == linked
    assert results["views_refined_linked"] == len(linked) and "refine_linked_s" in results["timings"]
    assert f"Registrable refinement (--min-matches 15, beyond the paper): kept {len(linked)} of" in printed
    stamp = (tmp_path / "full_scan" / "transforms.json").stat().st_mtime_ns
    online = results["online"]
    assert 2 <= online["policy"]["views"] <= 4 and online["random"]["views"] == online["policy"]["views"]
    assert online["orbit"]["views"] == online["orbit2"]["views"] == online["policy"]["views"]  # tuned orbits
    assert online["lookahead"]["views"] == online["policy"]["views"]  # the depth option
    assert online["lookahead-stereo"]["views"] == online["policy"]["views"]  # the image-only look-ahead
    assert 0 < online["policy"]["gt"]["coverage"] <= 1
    assert online["policy"]["flight_m"] > 0 and "| flight (m) | azimuth reversals |" in printed
    assert (tmp_path / "online_policy" / "trajectory.png").is_file()
    assert main([*args, "--no-online"]) == 0
    assert (tmp_path / "full_scan" / "transforms.json").stat().st_mtime_ns == stamp  # not re-rendered
    assert json.loads((tmp_path / "results.json").read_text())["online"] == {}
