"""Part 7: mesh inputs, through `nbv scene export` and `nbv scan`."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from probe.harness import Case, Result, sh

BOX_V = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (0.0, 1.0)]
BOX_F = [
    (1, 2, 4),
    (1, 4, 3),
    (5, 7, 8),
    (5, 8, 6),
    (1, 5, 6),
    (1, 6, 2),
    (3, 4, 8),
    (3, 8, 7),
    (1, 3, 7),
    (1, 7, 5),
    (2, 6, 8),
    (2, 8, 4),
]
EXPORT, SCAN2 = "nbv scene export model.obj --out D", "nbv scan model.obj circle --views 2 $CAM --out s"


def obj(
    head: str = "",
    faces: list[tuple[int, ...]] | None = None,
    body: str = "",
    name: str = "model.obj",
    texture: str = "",
) -> Callable[[Path], None]:
    """Setup: a unit box OBJ (`head` lines first, `faces` instead of the box's, or `body` instead of all)
    with, when `texture` is a shell snippet, a material whose texture that snippet writes as tex.png."""

    def setup(folder: Path) -> None:
        lines = [f"v {x} {y} {z}" for x, y, z in BOX_V] + [f"vt {u} {v}" for u in (0, 1) for v in (0, 1)]
        lines += ["f " + " ".join(f"{i}/{1 + k % 4}" for k, i in enumerate(f)) for f in (faces or BOX_F)]
        (folder / name).write_text(head + (body or "\n".join(lines)) + "\n")
        if texture:
            (folder / "m.mtl").write_text(f"newmtl a\nKd 1 1 1\n{texture}\n")
            sh(
                '$PYTHON -c "import numpy as n; from PIL import Image; '
                'Image.fromarray((n.indices((64, 64)).sum(0)'
                " % 2 * 255).astype('uint8')).convert('RGB').save('tex.png')\"",
                folder,
            )

    return setup


def textured(map_line: str, make: str = "") -> Callable[[Path], None]:
    """Setup: the box with `mtllib m.mtl`, `usemtl a` and `map_line`, then the shell `make`."""

    def setup(folder: Path) -> None:
        obj("mtllib m.mtl\nusemtl a\n", texture=map_line)(folder)
        if make:
            sh(make, folder)

    return setup


def interleaved(folder: Path) -> None:
    """F26: each face's three vertices, then `f -3 -2 -1`."""
    lines = []
    for face in BOX_F:
        lines += [f"v {BOX_V[i - 1][0]} {BOX_V[i - 1][1]} {BOX_V[i - 1][2]}" for i in face] + ["f -3 -2 -1"]
    (folder / "model.obj").write_text("\n".join(lines) + "\n")


def box_extent(folder: Path, result: Result) -> tuple[str, str] | None:
    """Check: D/mesh.ply spans the unit box (1 x 1 x 1)."""
    import trimesh

    mesh = trimesh.load(folder / "D/mesh.ply", force="mesh", process=False)
    extent = np.ptp(mesh.vertices, axis=0)
    if not np.allclose(sorted(extent), [1, 1, 1], atol=1e-3):
        return "silent", f"wrong geometry: extent {np.round(extent, 3).tolist()}, {len(mesh.faces)} faces"
    return None


def same_texture(folder: Path, result: Result) -> tuple[str, str] | None:
    """Check (F28): the scan with `map_Kd -s ... tex.png` renders as the one with `map_Kd tex.png`."""
    from PIL import Image

    textured("map_Kd tex.png")(folder)
    plain = sh(SCAN2.replace("--out s", "--out plain"), folder, 200)
    if plain.rc != 0:
        return "harness-error", "the plain-texture scan failed: " + plain.last
    if "warn" in result.output.lower():
        return "silent", "a warning for a valid texture: " + result.last
    diffs = [
        np.abs(
            np.asarray(Image.open(folder / f"s/images/{n}")).astype(int)
            - np.asarray(Image.open(folder / f"plain/images/{n}")).astype(int)
        ).max()
        for n in ("0000.png", "0001.png")
    ]
    return ("silent", f"renders differ from map_Kd tex.png by up to {max(diffs)}") if max(diffs) > 3 else None


def ply_ascii(folder: Path) -> None:
    """F29: an ASCII PLY declaring 10^7 faces, with a 12-face body."""
    head = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
    head += "element face 10000000\nproperty list uchar int vertex_indices\nend_header\n"
    body = "".join(f"{x} {y} {z}\n" for x, y, z in BOX_V) + "".join(
        f"3 {a - 1} {b - 1} {c - 1}\n" for a, b, c in BOX_F
    )
    (folder / "model.ply").write_text(head + body)


def ply_binary(folder: Path) -> None:
    """A binary PLY declaring 10^7 faces with a 12-face body (refused since d439c96)."""
    import struct

    head = "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
    head += "property float z\nelement face 10000000\nproperty list uchar int vertex_indices\nend_header\n"
    body = b"".join(struct.pack("<3f", *v) for v in BOX_V)
    body += b"".join(struct.pack("<B3i", 3, a - 1, b - 1, c - 1) for a, b, c in BOX_F)
    (folder / "model.ply").write_bytes(head.encode() + body)


# Part 7: F24-F29 and passing mesh inputs, through `nbv scene export` and `nbv scan`.
degenerate = [(1, 1, 2), (3, 3, 4), (5, 6, 6), (7, 8, 8)]
collinear = "\n".join(
    [f"v {i * 0.01} 0 0" for i in range(102)] + [f"f {i} {i + 1} {i + 2}" for i in range(1, 101)]
)
header30k = (
    "$PYTHON -c \"import struct,zlib;c=lambda k,b:struct.pack('>I',len(b))+k+b+struct.pack('>I',"
    "zlib.crc32(k+b));open('tex.png','wb').write(b'\\x89PNG\\r\\n\\x1a\\n'+c(b'IHDR',struct.pack("
    "'>IIBBBBB',30000,30000,8,2,0,0,0))+c(b'IDAT',zlib.compress(bytes(64)))+c(b'IEND',b''))\""
)
PART7 = [
    Case(
        7,
        "F24-fifo-mtllib",
        EXPORT,
        expect="warn",
        words=("m.mtl",),
        timeout=60,
        setup=lambda f: (obj("mtllib m.mtl\n")(f), os.mkfifo(f / "m.mtl")),
    ),
    Case(
        7,
        "F24-fifo-map_Kd-scan",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        timeout=90,
        setup=textured("map_Kd tex.png", "rm tex.png && mkfifo tex.png"),
    ),
    Case(7, "F25-zero-area-obj", SCAN2, words=("model.obj", "area"), setup=obj(faces=degenerate)),
    Case(7, "F25-collinear-obj", EXPORT, words=("model.obj", "area"), setup=obj(body=collinear)),
    Case(
        7,
        "F25-zero-area-stl",
        "nbv scene export model.stl --out D",
        words=("model.stl", "area"),
        setup='$PYTHON -c "import trimesh,numpy as n;trimesh.Trimesh(n.eye(3),[[0,0,1],[1,1,2]],'
        "process=False).export('model.stl')\"",
    ),
    Case(7, "F26-interleaved-negative", EXPORT, expect="ok", setup=interleaved, check=box_extent),
    Case(
        7,
        "F27-random-bytes-texture",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        setup=textured("map_Kd tex.png", "head -c 5000 /dev/urandom > tex.png"),
    ),
    Case(
        7,
        "F27-png-claims-30000",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        memory=2**31,
        setup=textured("map_Kd tex.png", header30k),
    ),
    Case(
        7,
        "F27-sparse-2GB-texture",
        SCAN2,
        expect="warn",
        words=("tex.png",),
        memory=2**30,
        setup=textured("map_Kd tex.png", "rm tex.png && truncate -s 2G tex.png"),
    ),
    Case(
        7,
        "F28-map_Kd-options",
        SCAN2,
        expect="ok",
        setup=textured("map_Kd -s 2 2 1 -o 0.5 0.5 0 tex.png"),
        check=same_texture,
        timeout=200,
    ),
    Case(
        7,
        "F29-ascii-ply-short",
        "nbv scene export model.ply --out D",
        words=("model.ply",),
        setup=ply_ascii,
    ),
    Case(
        7,
        "binary-ply-short",
        "nbv scene export model.ply --out D",
        words=("model.ply",),
        setup=ply_binary,
    ),
    Case(
        7,
        "plain-negative-indices",
        EXPORT,
        expect="ok",
        check=box_extent,
        setup=obj(
            body="\n".join(
                [f"v {x} {y} {z}" for x, y, z in BOX_V]
                + [f"f {a - 9} {b - 9} {c - 9}" for a, b, c in BOX_F]
            )
        ),
    ),
    Case(7, "valid-box", EXPORT, expect="ok", setup=obj(), check=box_extent),
    Case(7, "index-out-of-range", EXPORT, words=("model.obj",), setup=obj(faces=[(1, 2, 99)] + BOX_F)),
    Case(7, "index-before-start", EXPORT, words=("model.obj",), setup=obj(faces=[(-99, 1, 2)] + BOX_F)),
    Case(
        7,
        "map_Kd-etc-passwd",
        EXPORT,
        expect="warn",
        words=("passwd",),
        setup=textured("map_Kd ../../../../../../etc/passwd"),
    ),
    Case(
        7,
        "missing-texture",
        EXPORT,
        expect="warn",
        words=("nothere.png",),
        setup=textured("map_Kd nothere.png"),
    ),
    Case(7, "empty-obj", EXPORT, words=("model.obj",), setup="touch model.obj"),
    Case(7, "mesh-is-directory", EXPORT, words=("model.obj",), setup="mkdir model.obj"),
    Case(7, "mesh-missing", EXPORT, words=("model.obj",)),
    Case(7, "mesh-fifo", EXPORT, words=("model.obj",), setup="mkfifo model.obj", timeout=60),
    Case(
        7,
        "newline-unicode-name",
        "nbv scene export \"$(printf 'mo\\ndèl.obj')\" --out D",
        expect="either",
        setup=obj(name="mo\ndèl.obj"),
    ),
]


def part7() -> list[Case]:
    """Part 7: F24-F29 and passing mesh inputs, through `nbv scene export` and `nbv scan`."""
    return list(PART7)


