"""Part 5: dataset-reader mutations of DS8 through reconstruct, refine and export."""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np

from probe.harness import ENV, Case


def mutated(change: Callable[[Path], None]) -> Callable[[Path], None]:
    """Setup: a copy of DS8 at `d`, then `change(d)`."""

    def setup(folder: Path) -> None:
        shutil.copytree(ENV["DS8"], folder / "d", symlinks=True)
        change(folder / "d")

    return setup


def text(old: str, new: str) -> Callable[[Path], None]:
    """Replace the first `old` in d/transforms.json by `new`."""

    def change(root: Path) -> None:
        path = root / "transforms.json"
        body = path.read_text()
        assert old in body, old
        path.write_text(body.replace(old, new, 1))

    return change


def doc(edit: Callable[[dict], None]) -> Callable[[Path], None]:
    """Edit d/transforms.json as a dict."""

    def change(root: Path) -> None:
        path = root / "transforms.json"
        record = json.loads(path.read_text())
        edit(record)
        path.write_text(json.dumps(record, indent=1))

    return change


def short_idat(root: Path) -> None:
    """F14: images/0000.png's IDAT holding only its first 24 of 48 rows (a valid stream, valid CRCs)."""
    import struct
    import zlib

    path, data, chunks, pos = root / "images/0000.png", (root / "images/0000.png").read_bytes(), [], 8
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        chunks.append((kind, data[pos + 8 : pos + 8 + length]))
        pos += 12 + length
    raw = zlib.decompress(b"".join(body for kind, body in chunks if kind == b"IDAT"))
    chunks = [c for c in chunks if c[0] not in (b"IDAT", b"IEND")]
    chunks += [(b"IDAT", zlib.compress(raw[: (64 * 3 + 1) * 24])), (b"IEND", b"")]
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + b"".join(
            struct.pack(">I", len(b)) + k + b + struct.pack(">I", zlib.crc32(k + b)) for k, b in chunks
        )
    )


def apng(root: Path) -> None:
    """F16: an APNG whose default image is not part of the animation."""
    from PIL import Image

    path = root / "images/0000.png"
    still = Image.open(path).convert("RGB")
    still.save(path, save_all=True, append_images=[Image.new("RGB", still.size)], default_image=True)


def newline_name(root: Path) -> None:
    """F18: an image file name holding a newline."""
    os.rename(root / "images/0002.png", root / "images/00\n02.png")
    doc(lambda d: d["frames"][2].update(file_path="images/00\n02.png"))(root)


def many_frames(root: Path) -> None:
    """F19: 10^5 frames that all reference one image and depth."""
    doc(lambda d: d.update(frames=[d["frames"][0]] * 100_000))(root)


def interlaced(root: Path) -> None:
    """An Adam7-interlaced image (accepted harmlessly)."""
    from PIL import Image

    image = Image.open(root / "images/0001.png")
    image.save(root / "images/0001.png", interlace=1)


def fuzzed(seed: int) -> Callable[[Path], None]:
    """A mutation by the dataset fuzzer of tests/render/test_dataset_fuzz.py (JSON, text or PNG)."""

    def change(root: Path) -> None:
        from PIL import Image

        from tests.render import test_dataset_fuzz as fz

        rng = np.random.default_rng(seed)
        outside = root.parent / "outside.png"
        Image.fromarray(np.zeros((48, 64, 3), np.uint8)).save(outside)
        if seed % 4 == 3:
            fz._mutate_png(root, rng)
        elif seed % 8 == 2:
            fz._mutate_text(root, rng)
        else:
            fz._edit(
                root, lambda d: [fz._mutate_json(d, rng, outside) for _ in range(int(rng.integers(1, 3)))]
            )

    return change


def _reflect(d: dict) -> None:
    for row in d["frames"][0]["transform_matrix"][:3]:
        row[0] = -row[0]


# Part 5: F12-F19 and passing mutations of DS8 through reconstruct, refine and export.
rec, ref, exp = "nbv reconstruct d --out o", "nbv refine d --threads 1 --out o", "nbv export d --out e"
tj, frames = ("transforms.json",), ("transforms.json", "frames")
cases = [
    Case(
        5,
        "F12-dup-w",
        rec,
        words=("transforms.json", "twice"),
        setup=mutated(text('"w": 64', '"w": 32, "w": 64')),
    ),
    Case(
        5,
        "F12-dup-frames",
        rec,
        words=("transforms.json", "twice"),
        setup=mutated(text('"frames": [', '"frames": [], "frames": [')),
    ),
    Case(
        5,
        "F12-dup-fl_x-refine",
        ref,
        words=("transforms.json", "twice"),
        setup=mutated(text('"fl_x": ', '"fl_x": 1000.0, "fl_x": ')),
    ),
    Case(
        5,
        "F13-aabb-NaN",
        rec,
        words=("transforms.json", "nan"),
        setup=mutated(text('"w": 64', '"aabb_scale": NaN, "w": 64')),
    ),
    Case(
        5,
        "F13-extra-neg-infinity-refine",
        ref,
        words=("transforms.json", "infinity"),
        setup=mutated(
            text('"file_path": "images/0000.png"', '"extra": -Infinity, "file_path": "images/0000.png"')
        ),
    ),
    Case(5, "F14-short-idat", rec, words=("0000.png", "truncated"), setup=mutated(short_idat)),
    Case(5, "F14-short-idat-refine", ref, words=("0000.png", "truncated"), setup=mutated(short_idat)),
    Case(
        5,
        "F15-shared-image",
        rec,
        words=("same file", "pose"),
        setup=mutated(
            doc(
                lambda d: d["frames"][1].update(
                    file_path=d["frames"][0]["file_path"],
                    depth_file_path=d["frames"][0]["depth_file_path"],
                )
            )
        ),
    ),
    Case(5, "F16-apng", rec, words=("0000.png", "apng"), setup=mutated(apng)),
    Case(
        5,
        "F17-lone-surrogate",
        ref,
        words=("file_path", "surrogate"),
        setup=mutated(text('"images/0001.png"', '"images/0001\\ud800.png"')),
    ),
    Case(5, "F18-newline-name-export", exp, words=("file_path",), setup=mutated(newline_name)),
    Case(5, "F19-1e5-frames-refine", ref, expect="either", setup=mutated(many_frames), timeout=150),
    Case(
        5,
        "empty-frame-objects",
        rec,
        words=frames,
        setup=mutated(doc(lambda d: d.update(frames=[{}, {}]))),
    ),
    Case(
        5,
        "proc-environ-symlink",
        rec,
        words=tj,
        setup=mutated(
            lambda r: (
                (r / "transforms.json").unlink(),
                (r / "transforms.json").symlink_to("/proc/self/environ"),
            )
        ),
    ),
    Case(
        5,
        "bare-NaN-fl_x",
        rec,
        words=("fl_x",),
        setup=mutated(text('"fl_x": 62.22222222222222', '"fl_x": NaN')),
    ),
    Case(5, "k1-string", rec, words=("k1",), setup=mutated(doc(lambda d: d.update(k1="0")))),
    Case(5, "k3-tiny", rec, expect="either", setup=mutated(doc(lambda d: d.update(k3=1e-300)))),
    Case(
        5,
        "camera-model-lower",
        rec,
        words=("camera_model",),
        setup=mutated(doc(lambda d: d.update(camera_model="opencv"))),
    ),
    Case(5, "5000-digit-int", rec, words=tj, setup=mutated(text('"w": 64', '"w": ' + "9" * 5000))),
    Case(5, "reflection", rec, words=("rotation",), setup=mutated(doc(_reflect))),
    Case(
        5,
        "folder-as-file-path",
        rec,
        words=("0000.png",),
        setup=mutated(lambda r: ((r / "images/0000.png").unlink(), (r / "images/0000.png").mkdir())),
    ),
    Case(
        5,
        "symlink-png-outside",
        rec,
        words=("0000.png",),
        setup=mutated(
            lambda r: (
                shutil.copy(r / "images/0000.png", r.parent / "out.png"),
                (r / "images/0000.png").unlink(),
                (r / "images/0000.png").symlink_to(r.parent / "out.png"),
            )
        ),
    ),
    Case(
        5,
        "duplicate-identical-frames",
        rec,
        expect="either",
        setup=mutated(doc(lambda d: d["frames"].append(dict(d["frames"][0])))),
    ),
    Case(
        5,
        "source-index-2^70",
        rec,
        expect="either",
        setup=mutated(doc(lambda d: d["frames"][0].setdefault("nbv", {}).update(source_index=2**70))),
    ),
    Case(5, "interlaced-png", rec, expect="ok", setup=mutated(interlaced)),
    Case(
        5,
        "unicode-space-name",
        rec,
        expect="ok",
        setup=mutated(
            lambda r: (
                os.rename(r / "images/0003.png", r / "images/vue 3 é.png"),
                doc(lambda d: d["frames"][3].update(file_path="images/vue 3 é.png"))(r),
            )
        ),
    ),
]
cases += [
    Case(5, f"fuzz-{seed}", rec, expect="either", setup=mutated(fuzzed(seed))) for seed in range(12)
]
PART5 = cases


def part5() -> list[Case]:
    """Part 5: F12-F19 and passing mutations of DS8 through reconstruct, refine and export."""
    return list(PART5)


