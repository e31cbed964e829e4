"""Cache entries (issue 28): one writer per entry, and a write that fails (a full disk, a cache folder that
cannot be written) is one warning naming the entry and the errno, the command going on with its value."""

from __future__ import annotations

import errno
import os
import signal
import warnings
from pathlib import Path

import numpy as np
import pytest
from lock_holder import hold
from PIL import Image

from common.cache import cache_file, write_cache
from common.locks import lock_file
from scenes.loader import load_file_scene
from scenes.textures import make_texture, texture_path

TRIANGLE_OBJ = "v 0 0 0\nv 2 0 0\nv 0 1 3\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n"


def full_disk_under(folder: Path, write):
    """`write`, raising ENOSPC (as a full disk does) when it writes under `folder`."""
    def writing(tmp: Path) -> None:
        if folder in tmp.parents:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(tmp))
        write(tmp)
    return writing


def test_an_entry_another_run_writes_is_left_to_it_and_written_once_it_is_free(tmp_path):
    entry = tmp_path / "cache" / "key.pt"
    holder = hold(entry)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert write_cache(entry, lambda tmp: pytest.fail("wrote another run's entry")) is False
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
        holder.stdout.close()
    assert write_cache(entry, lambda tmp: tmp.write_text("v")) is True
    assert entry.read_text() == "v" and not lock_file(entry).exists()


def test_a_full_disk_under_a_file_entry_warns_once_and_hands_on_a_temporary_copy(tmp_path):
    cache = tmp_path / "cache"
    entry = cache / "textures" / "a.txt"
    write = full_disk_under(cache, lambda tmp: tmp.write_text("texels"))
    with pytest.warns(UserWarning, match=rf"^cache {entry} not written \(no space left on device "
                                         r"\(ENOSPC\)\); going on without it$") as caught:
        copy = cache_file(entry, write)
    assert len(caught) == 1 and copy.read_text() == "texels" and cache not in copy.parents
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # warned once: the copy is used now, the folder not reported again
        assert cache_file(entry, write) == copy
        assert cache_file(entry.with_name("b.txt"), write).read_text() == "texels"
    assert sorted(p.name for p in entry.parent.iterdir()) == []  # nothing partial left in the cache


def test_procedural_texture_in_an_unwritable_cache_is_a_warning_and_the_same_texels(tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    cache.mkdir()
    (cache / "textures").write_text("a file where the folder should be")
    monkeypatch.setenv("NBV_CACHE_DIR", str(cache))
    with pytest.warns(UserWarning, match=r"^cache \S*/textures/gravel_s7_16px\S* not written \(.*EEXIST"):
        path = texture_path("gravel", 7, 16)
    assert np.array_equal(np.asarray(Image.open(path)), make_texture("gravel", 7, 16))


def test_mesh_texture_on_a_full_cache_disk_is_a_warning_and_the_mesh_still_loads(tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    monkeypatch.setenv("NBV_CACHE_DIR", str(cache))
    image = np.zeros((8, 8, 3), np.uint8)
    image[:, :, 1] = 255
    Image.fromarray(image).save(tmp_path / "tex.png")
    (tmp_path / "m.mtl").write_text("newmtl a\nKd 1 1 1\nmap_Kd tex.png\n")
    (tmp_path / "model.obj").write_text(f"mtllib m.mtl\nusemtl a\n{TRIANGLE_OBJ}")
    real = Path.write_bytes
    monkeypatch.setattr(Path, "write_bytes", lambda self, data: full_disk_under(cache, lambda tmp: real(
        tmp, data))(self))
    with pytest.warns(UserWarning, match=r"^cache .*/mesh_textures/.*\.png not written \(no space left on "
                                         r"device \(ENOSPC\)"):
        (part,) = load_file_scene(tmp_path / "model.obj", ground=False).parts
    assert np.array_equal(np.asarray(Image.open(part.material.texture)), image)
