"""One writer per output, full disks and `--out` itself (issue 28): a second run on an output fails at once
naming the first, nothing a run did not write is replaced, a write error is one line naming the path and
the errno, a failing cache write only warns, a bad `--out` is refused before any work."""

from __future__ import annotations

import errno
import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
import torch
import trimesh
from lock_holder import hold
from PIL import Image
from synthetic import write_circle_dataset

from common.io import atomic_folder
from common.locks import lock_file
from nbv.cli import main
from nbv.fanout.ray_pool import check_reachable
from nbv.features.cache import save_features
from nbv.features.sift import DESCRIPTOR_DIM, Features
from render.dataset import read_dataset

ROOT = Path(__file__).resolve().parents[3]
SCAN = ["scan", "test_building", "circle", "--width", "64", "--height", "48", "--spp", "1"]
ENOSPC = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def one_line(capsys: pytest.CaptureFixture) -> str:
    """The one error line a command printed (after its progress bar, if any)."""
    err = capsys.readouterr().err.strip()
    lines = [line for line in re.split(r"[\r\n]+", err) if line.startswith("nbv ")]
    assert len(lines) == 1 and err.endswith(lines[0]) and "Traceback" not in err, err
    return lines[0]


def leftovers(out: Path) -> list[str]:
    """What runs leave beside `out`: temporary folders, set-aside outputs, lock files."""
    return sorted(p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}."))


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    return write_circle_dataset(tmp_path_factory.mktemp("writers") / "ds", [1, 2, 3], size=(64, 48))


def test_two_scans_one_out_exactly_one_wins(tmp_path, capsys):
    out = tmp_path / "same"
    first = subprocess.Popen([sys.executable, "-m", "nbv.cli", *SCAN, "--views", "4", "--seed", "5",
                              "--out", str(out)], env={**os.environ, "PYTHONPATH": str(ROOT)},
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while first.poll() is None and time.monotonic() < deadline and not lock_file(out).exists():
        time.sleep(0.005)  # the first run holds --out from its start on
    second = main([*SCAN, "--views", "2", "--seed", "7", "--out", str(out)])
    err = one_line(capsys)
    assert first.wait() == 0, first.stderr.read()
    assert second == 2
    if "being written" in err:  # it came while the first ran: refused at once, naming it
        assert err == (f"nbv scan: error: {out} is being written by another run (pid {first.pid}); wait for "
                       "it to finish, or pass --wait-for-lock to wait")
    else:  # it came after the first was done
        assert f"output folder {out} exists and is not empty" in err, err
    assert len(read_dataset(out)) == 4 and leftovers(out) == []


def test_wait_for_lock_waits_for_the_other_run_then_writes(tmp_path, capsys):
    out = tmp_path / "scan"
    holder = hold(out, seconds=1.0)
    assert main([*SCAN, "--views", "2", "--out", str(out), "--wait-for-lock"]) == 0
    assert holder.wait() == 0 and len(read_dataset(out)) == 2 and leftovers(out) == []


def test_reconstruct_overwrite_while_evaluate_writes_the_folder_fails_at_once(dataset, tmp_path, capsys):
    out = tmp_path / "recon"
    out.mkdir()
    (out / "mesh.ply").write_text("the old mesh")
    evaluating = hold(out)  # `nbv evaluate ... --out recon` at work (F4)
    try:
        assert main(["reconstruct", str(dataset), "--out", str(out), "--overwrite"]) == 2
        assert f"(pid {evaluating.pid})" in one_line(capsys)
    finally:
        evaluating.kill()
        evaluating.wait()
    assert (out / "mesh.ply").read_text() == "the old mesh"


def test_carried_files_are_taken_at_the_swap_not_at_the_start(tmp_path):
    out = tmp_path / "recon"
    out.mkdir()
    (out / "metrics.json").write_text("old")
    with atomic_folder(out, overwrite=True, outputs=("mesh.ply",)) as tmp:
        (tmp / "mesh.ply").write_text("new mesh")
        (out / "metrics.json").write_text("written meanwhile")
    assert {p.name: p.read_text() for p in out.iterdir()} == {"mesh.ply": "new mesh",
                                                              "metrics.json": "written meanwhile"}


def test_an_output_that_appeared_while_the_run_ran_is_never_replaced(tmp_path):
    out = tmp_path / "scan"
    with pytest.raises(FileExistsError, match="appeared while this run ran; nothing was replaced"):
        with atomic_folder(out) as tmp:
            (tmp / "mine.txt").write_text("mine")
            out.mkdir()
            (out / "theirs.txt").write_text("theirs")
    assert [p.name for p in out.iterdir()] == ["theirs.txt"] and leftovers(out) == []


def test_symlinked_out_is_written_through_and_stays_a_link(tmp_path, capsys):
    real, link = tmp_path / "real", tmp_path / "link"
    real.mkdir()
    (real / "old.txt").write_text("old")
    link.symlink_to(real)
    with atomic_folder(link, overwrite=True) as tmp:
        (tmp / "new.txt").write_text("new")
    assert link.is_symlink() and [p.name for p in real.iterdir()] == ["new.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_disk_full_in_scan_is_one_line_naming_the_file(tmp_path, capsys, monkeypatch):
    def full(self, fp, *args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(fp))

    monkeypatch.setattr(Image.Image, "save", full)
    out = tmp_path / "scan"
    assert main([*SCAN, "--views", "2", "--out", str(out)]) == 1
    full_disk = "no space left on device (ENOSPC)"
    assert one_line(capsys) == f"nbv scan: error: {full_disk} writing {out}/images/0000.png"
    assert not out.exists() and leftovers(out) == []


def test_disk_full_in_reconstruct_keeps_the_old_output_and_names_the_mesh(dataset, tmp_path, capsys,
                                                                          monkeypatch):
    out = tmp_path / "recon"
    out.mkdir()
    (out / "mesh.ply").write_text("old")
    monkeypatch.setattr(trimesh.Trimesh, "export", lambda *a, **k: (_ for _ in ()).throw(ENOSPC))
    fast = ["--voxel-size-m", "0.02", "--truncation-m", "0.08"]
    assert main(["reconstruct", str(dataset), "--out", str(out), "--overwrite", *fast]) == 1
    full_disk = "no space left on device (ENOSPC)"
    assert one_line(capsys) == f"nbv reconstruct: error: {full_disk} writing {out}/mesh.ply"
    assert [p.name for p in out.iterdir()] == ["mesh.ply"] and (out / "mesh.ply").read_text() == "old"
    assert leftovers(out) == []


def test_a_failing_feature_cache_write_is_only_a_warning_naming_the_errno(tmp_path, monkeypatch):
    monkeypatch.setattr(Path, "write_bytes", lambda *a, **k: (_ for _ in ()).throw(ENOSPC))  # full disk (F6)
    path = tmp_path / "cache" / "key.pt"
    with pytest.warns(UserWarning, match=rf"^cache {path} not written \(no space left on device \(ENOSPC"):
        save_features(path, [Features(torch.zeros(1, 2), torch.zeros(1, DESCRIPTOR_DIM), torch.zeros(1))])
    assert sorted(p.name for p in path.parent.iterdir()) == []


def test_scan_with_an_unwritable_texture_cache_warns_in_one_line_and_succeeds(tmp_path):
    cache = tmp_path / "cache"
    cache.mkdir()
    (cache / "textures").write_text("a file where the folder should be")
    scan = [sys.executable, "-m", "nbv.cli", *SCAN, "--views", "2", "--out", str(tmp_path / "s")]
    done = subprocess.run(scan, env={**os.environ, "PYTHONPATH": str(ROOT), "NBV_CACHE_DIR": str(cache)},
                          capture_output=True, text=True, timeout=300)
    warned = [line for line in re.split(r"[\r\n]+", done.stderr) if "warning" in line]
    assert done.returncode == 0 and len(read_dataset(tmp_path / "s")) == 2, done.stderr
    line = (rf"nbv scan: warning: cache {cache}/textures/\S+\.png not written \(file exists \(EEXIST\) at "
            rf"{cache}/textures\); going on without it")
    assert len(warned) == 1 and re.fullmatch(line, warned[0]), done.stderr  # one for all the scene's textures


def test_disk_full_in_refine_is_one_line_naming_the_output(dataset, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(Image.Image, "save", lambda *a, **k: (_ for _ in ()).throw(ENOSPC))
    out = tmp_path / "kept"
    assert main(["refine", str(dataset), "--ranges", "1", "--words", "4", "--out", str(out)]) == 1
    assert one_line(capsys) == f"nbv refine: error: no space left on device (ENOSPC) writing {out}"
    assert not out.exists() and leftovers(out) == []


@pytest.mark.parametrize("command", [["train"], SCAN, ["reconstruct", "DS"]])
def test_empty_out_is_refused_naming_it(command, capsys):
    assert main([*command, "--out", ""]) == 2
    assert one_line(capsys).endswith("error: --out is empty: name the output folder (e.g. --out runs/scan1)")


@pytest.mark.parametrize("out", ["x" * 5000, "/".join(["y" * 200] * 25)])
def test_over_long_out_names_enametoolong(out, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main([*SCAN, "--views", "2", "--out", out]) == 2
    err = one_line(capsys)
    assert "ENAMETOOLONG" in err and len(err) < 200, err


def test_dangling_symlink_out_is_refused(tmp_path, capsys):
    link = tmp_path / "dangling"
    link.symlink_to(tmp_path / "nowhere")
    assert main([*SCAN, "--views", "2", "--out", str(link)]) == 2
    assert one_line(capsys) == (f"nbv scan: error: output {link} is a symlink to {tmp_path / 'nowhere'}, "
                                "which does not exist (remove the link or create its target)")
    assert link.is_symlink() and not (tmp_path / "nowhere").exists()


def test_export_out_inside_its_dataset_is_refused(dataset, capsys):
    out = dataset / "images" / "x"
    assert main(["export", str(dataset), "--out", str(out), "--overwrite"]) == 2
    assert "must not be the input folder" in one_line(capsys) and not out.exists()


def test_out_that_is_the_current_folder_is_refused(dataset, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["reconstruct", str(dataset), "--out", ".", "--overwrite"]) == 2
    assert "output folder . is the current folder or holds it" in one_line(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_ray_address_with_nothing_listening_fails_within_seconds(tmp_path, capsys):
    with socket.socket() as probe:  # a local port nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    start = time.monotonic()
    train = ["train", "--ray", f"127.0.0.1:{port}", "--out", str(tmp_path / "run")]
    assert main(train) == 2  # before any work
    assert one_line(capsys).startswith(f"nbv train: error: ray 127.0.0.1:{port}: nothing answers")
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match=rf"^ray 127.0.0.1:{port}: nothing answers at 127.0.0.1:{port} "
                                         r"within 5 s \(connection refused \(ECONNREFUSED\)"):
        check_reachable(f"127.0.0.1:{port}")
    silent = "ray://192.0.2.2:9"  # a documentation address: no answer at all
    with pytest.raises(ValueError, match=rf"^ray {silent}: nothing answers at 192.0.2.2:9 within 0.2"):
        check_reachable(silent, timeout_s=0.2)
    assert time.monotonic() - start < 3.0


def test_ray_address_of_no_known_form_is_refused_naming_the_option(tmp_path, capsys):
    assert main(["train", "--ray", "garbage-address", "--out", str(tmp_path / "run")]) == 2
    assert one_line(capsys) == ("nbv train: error: --ray must be 'auto', HOST:PORT or ray://HOST:PORT, "
                                "got 'garbage-address'")
    assert sorted(p.name for p in tmp_path.iterdir()) == []
