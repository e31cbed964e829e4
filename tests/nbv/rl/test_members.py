"""Several training seeds in one command: member seeds, the kept actor, and its files."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest
import torch

from nbv.cli import main
from nbv.rl.checkpoint import load_checkpoint, load_policy
from nbv.rl.command import train_command
from nbv.rl.config import MembersConfig, ValidationConfig
from nbv.rl.members import member_config
from tests.nbv.rl.test_train import TINY_ENV
from tests.nbv.rl.test_validate import cache, validated  # noqa: F401 (fixture)


def test_members_take_disjoint_seeds_and_their_own_folders(tmp_path):
    config = validated(tmp_path, 4)
    config = replace(config, collector=replace(config.collector, seed=2), members=MembersConfig(3))
    members = [member_config(config, k) for k in range(3)]
    assert [m.collector.seed for m in members] == [6, 7, 8]  # command seed 2 of 3 members
    assert [m.logger.out for m in members] == [tmp_path / f"member{k}" for k in range(3)]
    assert all(m.members.count == 1 and m.validation.validation_scenes == ("test_building",)
               for m in members)


def test_members_keep_the_best_validated_actor_under_the_commands_config(tmp_path, cache):  # noqa: F811
    config = validated(tmp_path / "run", 4)
    config = replace(config, collector=replace(config.collector, seed=1), members=MembersConfig(2))
    kept_ckpt = train_command(config)

    with open(tmp_path / "run" / "members.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(int(r["member"]), int(r["seed"])) for r in rows] == [(0, 2), (1, 3)]
    best = [load_checkpoint(tmp_path / "run" / f"member{k}" / "checkpoint.pt")["validation"] for k in (0, 1)]
    kept = 0 if best[0]["score"] >= best[1]["score"] else 1
    assert [int(r["kept"]) for r in rows] == [int(k == kept) for k in (0, 1)]
    assert [float(r["best_score"]) for r in rows] == pytest.approx([b["score"] for b in best], abs=1e-3)
    assert kept_ckpt == tmp_path / "run" / f"member{kept}" / "checkpoint.pt"

    command, weights = load_policy(tmp_path / "run" / "policy.pt")
    _, member_weights = load_policy(tmp_path / "run" / f"member{kept}" / "policy.pt")
    assert all(torch.equal(weights[k], member_weights[k]) for k in member_weights)
    assert command["members"]["count"] == 2 and command["collector"]["seed"] == 1  # the command's
    member = json.loads((tmp_path / "run" / f"member{kept}" / "config.json").read_text())
    assert member["collector"]["seed"] == 2 + kept and member["members"]["count"] == 1
    assert (tmp_path / "run" / "training.png").stat().st_size > 10_000

    shipped = tmp_path / "shipped"  # what scripts/ship_policy.py commits: no machine path in it
    script = Path(__file__).parents[3] / "scripts" / "ship_policy.py"
    subprocess.run([sys.executable, str(script), "--run", str(tmp_path / "run"), "--dest", str(shipped),
                    "--name", "runs/default"], check=True, cwd=script.parents[1])
    files = sorted(str(p.relative_to(shipped)) for p in shipped.rglob("*") if p.is_file())
    assert files == ["config.json", "member0/config.json", "member0/metrics.csv", "member0/validation.csv",
                     "member1/config.json", "member1/metrics.csv", "member1/validation.csv", "members.csv",
                     "policy.pt", "training.png"]
    texts = [(shipped / f).read_text() for f in files if not f.endswith((".pt", ".png"))]
    assert not any(str(tmp_path) in text for text in texts)
    member1 = json.loads((shipped / "member1" / "config.json").read_text())
    assert member1["logger"]["out"] == "runs/default/member1"
    _, shipped_weights = load_policy(shipped / "policy.pt")
    assert all(torch.equal(shipped_weights[k], weights[k]) for k in weights)


def test_members_need_validation_buildings(tmp_path, capsys):
    config = validated(tmp_path, 2)
    with pytest.raises(ValueError, match="validation-scenes"):
        replace(config, validation=ValidationConfig(), members=MembersConfig(2))
    with pytest.raises(ValueError, match="members must be >= 1"):
        MembersConfig(0)
    args = ["train", *TINY_ENV, "--members", "2", "--frames", "2", "--out", str(tmp_path), "--no-progress"]
    assert main(args) == 2
    assert "members (2) are compared on validation buildings" in capsys.readouterr().err
