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
