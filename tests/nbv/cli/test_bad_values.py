"""Command-line values that would crash or mislead the renderer, TSDF or torch are refused up front:
exit status 2 and one line naming the field (issue 13)."""

from __future__ import annotations

import json

import pytest
import torch
from synthetic import write_circle_dataset

from nbv.cli import main
from nbv.rl.checkpoint import FORMAT, REQUIRED, VERSION

SCAN = ["scan", "test_building", "--out", "{tmp}/scan"]
TRAIN = ["train", "--scene", "test_building", "--out", "{tmp}/run"]
PLAN = ["plan", "test_building", "--out", "{tmp}/plan"]
REFINE = ["refine", "{tmp}/ds", "--out", "{tmp}/r"]
RECON = ["reconstruct", "{tmp}/ds", "--out", "{tmp}/rec"]

CASES = [
    (SCAN + ["--focal-mm", "1e308"], "focal_mm"),
    (SCAN + ["--focal-mm", "1e-300"], "focal_mm"),
    (SCAN + ["--spp", "1000000000000"], "spp"),
    (SCAN + ["--radius", "1e308"], "radius"),
    (SCAN + ["--radius", "1e-9"], "radius"),
    (SCAN + ["--radius", "0.5"], "radius"),
    (SCAN + ["circle", "--views", "10000000"], "views"),
    (SCAN + ["circle", "--views", "None", "--end-overlap", "0.99999999"], "end_overlap"),
    (SCAN + ["--end-overlap", "0.99999999"], "end_overlap"),
    (PLAN + ["--views", "0"], "views"),
    (PLAN + ["--metric-points", "0"], "--metric-points"),
    (PLAN + ["--planner", "circle", "--candidates", "0"], "--candidates"),
    (SCAN + ["--seed", "-5"], "--seed"),
    (TRAIN + ["--gamma", "2"], "gamma"),
    (TRAIN + ["--gamma", "0"], "gamma"),
    (TRAIN + ["--batch-size", "0"], "batch_size"),
    (TRAIN + ["--reward-scale", "nan"], "reward_scale"),
    (TRAIN + ["--alpha", "-1"], "alpha"),
    (TRAIN + ["--lr", "inf"], "lr"),
    (TRAIN + ["--target-tau", "2"], "target_tau"),
    (TRAIN + ["--radius-min", "0.5"], "radius_min"),
    (REFINE + ["--ranges", "1000000000"], "ranges"),
    (REFINE + ["--words", "1000000000"], "words"),
    (REFINE + ["--device", "xyz"], "device"),
    (REFINE + ["--threads", "-1"], "threads"),
    (REFINE + ["--seed", "-1"], "seed"),
    (["refine", "{tmp}/ds", "--out", "{tmp}/ds", "--overwrite"], "out"),
    (["refine", "{tmp}/ds", "--out", "{tmp}", "--overwrite"], "out"),
    (RECON + ["--block-resolution", "100000"], "block_resolution"),
    (RECON + ["--initial-blocks", "1000000000000"], "initial_blocks"),
    (["reconstruct", "{tmp}/ds", "--out", "{tmp}/ds/sub"], "out"),
]


@pytest.mark.parametrize(("argv", "field"), CASES, ids=[f"{c[0][0]} {c[1]} {c[0][-1]}" for c in CASES])
def test_bad_value_exits_2_naming_the_field(argv, field, tmp_path, capsys):
    (tmp_path / "ds").mkdir()
    assert main([a.replace("{tmp}", str(tmp_path)) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err and "Traceback" not in err, err
    assert not (tmp_path / "r").exists() and not (tmp_path / "rec").exists()


def test_refine_device_without_cuda_is_a_clear_error(tmp_path, capsys):
    if torch.cuda.is_available():
        pytest.skip("this machine has a CUDA GPU")
    assert main(["refine", str(tmp_path / "ds"), "--out", str(tmp_path / "r"), "--device", "cuda"]) == 2
    assert "device 'cuda'" in capsys.readouterr().err


def checkpoint(path, config, loss=None):
    """A well-formed checkpoint file whose config (JSON text or any value) and loss are as given."""
    state = dict.fromkeys(REQUIRED, {})
    state.update(format=FORMAT, version=VERSION, config=config, loss={} if loss is None else loss)
    torch.save(state, path)
    return path


ENV = {"scenes": {"scene": ["test_building"]}}
HOSTILE = {
    "no_env": json.dumps({"network": {}}),
    "unknown_key": json.dumps({"env": {**ENV, "colour": 1}, "network": {}}),
    "negative_history": json.dumps({"env": {**ENV, "history": -1}, "network": {}}),
    "zero_channels": json.dumps({"env": ENV, "network": {"channels": 0}}),
    "not_json": "{env: 1",
    "not_text": 3,
    "list": json.dumps([1, 2]),
    "loss_tensor": (json.dumps({"env": ENV, "network": {}}), torch.zeros(2)),
}


@pytest.mark.parametrize("case", list(HOSTILE))
def test_hostile_checkpoint_config_is_a_checkpoint_error(case, tmp_path, capsys):
    config, loss = HOSTILE[case] if isinstance(HOSTILE[case], tuple) else (HOSTILE[case], None)
    path = checkpoint(tmp_path / "ck.pt", config, loss)
    assert main(["plan", "test_building", "--planner", f"policy:{path}", "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err, err
    assert not (tmp_path / "p").exists()


def test_dataset_without_frames_names_the_file_and_field(tmp_path, capsys):
    source = write_circle_dataset(tmp_path / "ds", [0, 1], size=(32, 24))
    doc = json.loads((source / "transforms.json").read_text())
    (source / "transforms.json").write_text(json.dumps({**doc, "frames": []}))
    assert main(["reconstruct", str(source), "--out", str(tmp_path / "rec")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "transforms.json: field frames is empty" in err, err
    assert not (tmp_path / "rec").exists()


def _one_line_naming(capsys, *words: str) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err and all(w in err for w in words), err
    return err


@pytest.mark.parametrize(("argv", "words"), [
    (PLAN + ["--planner", "circle", "--views", "2", "--metric-points", "1000000000000"],
     ("--metric-points", "GiB", "use fewer points")),
    (PLAN + ["--planner", "infogain", "--views", "2", "--grid-resolution", "100000"],
     ("grid_resolution 100000", "GiB", "--grid-resolution")),
    (PLAN + ["--planner", "circle", "--views", "1000000000"], ("views must lie in [1, 100000]",)),
    (PLAN + ["--planner", "circle", "--views", "90000", "--width", "16384", "--height", "16384"],
     ("views 90000 at 16384x16384", "GiB", "--views")),
], ids=["metric_points_1e12", "grid_resolution_1e5", "plan_views_1e9", "plan_views_by_memory"])
def test_memory_sized_values_bounded_before_allocation(argv, words, tmp_path, capsys):
    assert main([a.replace("{tmp}", str(tmp_path)) for a in argv]) == 2
    _one_line_naming(capsys, *words)
    assert not (tmp_path / "plan").exists()


def test_memory_bound_follows_this_machines_memory(monkeypatch):
    """The bound is half the physical memory: 10^6 metric points pass with 1 GiB, not with 256 MiB."""
    from common import memory
    from nbv.recon.config import MetricsConfig

    monkeypatch.setattr(memory, "physical_memory", lambda: 2**30)
    assert MetricsConfig(n_points=1_000_000).n_points == 1_000_000
    monkeypatch.setattr(memory, "physical_memory", lambda: 2**28)
    with pytest.raises(memory.MemoryBoundError, match="0.238 GiB, more than 50% of this machine's 0.25 GiB"):
        MetricsConfig(n_points=1_000_000)


def test_many_frames_sharing_one_image_bounded_by_memory(tmp_path, capsys, monkeypatch):
    """Frames naming one 32x24 image, scaled down (500 frames, a 256 MiB machine) from the probe's 10^5 on
    16 GiB: refine refuses before extracting (262 MB of features at 500 a view, more than half the memory)
    instead of growing past it."""
    from common import memory

    monkeypatch.setattr(memory, "physical_memory", lambda: 2**28)
    source = write_circle_dataset(tmp_path / "ds", [0], size=(32, 24))
    doc = json.loads((source / "transforms.json").read_text())
    (source / "transforms.json").write_text(json.dumps({**doc, "frames": doc["frames"] * 500}))
    assert main(["refine", str(source), "--out", str(tmp_path / "r")]) == 2
    last = capsys.readouterr().err.replace("\r", "\n").strip().splitlines()[-1]  # after the progress bar
    assert last.startswith("nbv refine: error: refine of 500 views"), last
    assert "0.244 GiB" in last and "--max-features" in last
    assert not (tmp_path / "r").exists()


def test_unknown_variant_from_the_environment_names_the_variable(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("NBV_VARIANT", "bogus")
    assert main(["scan", "test_building", "circle", "--views", "2", "--width", "32", "--height", "24",
                 "--out", str(tmp_path / "scan")]) == 2
    _one_line_naming(capsys, "unknown Mitsuba variant 'bogus' (from $NBV_VARIANT)")
    assert not (tmp_path / "scan").exists()


def test_tiny_voxel_size_refused(tmp_path, capsys):
    source = write_circle_dataset(tmp_path / "ds", [0, 1], size=(32, 24))
    assert main(["reconstruct", str(source), "--out", str(tmp_path / "rec"), "--voxel-size-m", "1e-9"]) == 2
    _one_line_naming(capsys, "voxel_size_m must be at least 0.0001 m")
    assert not (tmp_path / "rec").exists()


@pytest.mark.parametrize(("argv", "words"), [
    (SCAN + ["--seed", "1e3"], ("--seed must be a whole number", "'1e3'")),
    (SCAN + ["--width", "0x40"], ("--width must be a whole number", "'0x40'")),
    (SCAN + ["circle", "--views", "8.5"], ("--views must be a whole number", "'8.5'")),
    (PLAN + ["--seed", "-5"], ("seed must be >= 0",)),
    (["export", "{tmp}/ds", "--out", "{tmp}/e", "--seed", "-5"], ("seed must be >= 0",)),
], ids=["scan_seed_1e3", "scan_width_hex", "scan_views_fraction", "plan_seed_negative",
                                  "export_seed_negative"])
def test_int_parse_errors_name_the_option(argv, words, tmp_path, capsys):
    (tmp_path / "ds").mkdir()
    assert main([a.replace("{tmp}", str(tmp_path)) for a in argv]) == 2
    _one_line_naming(capsys, *words)
