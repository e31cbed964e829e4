"""What a mesh file brings with it, checked before trimesh trusts it: referenced files, OBJ indices, PLY
counts, and textures trimesh would drop without a word.

- `GuardedResolver` opens a referenced file (an OBJ's `mtllib` and `map_Kd`, a glTF's buffers and
  images, a DAE's images) only when it is a regular file inside the mesh's folder and at most
  `MAX_ASSET_BYTES` long: a FIFO would block the loader, a sparse file would be read whole. It drops the
  options before a `map_Kd` file name, which trimesh would read as part of the name.
- `resolve_obj_indices` turns an OBJ's negative (relative) indices into absolute ones against the counts
  so far, as the format says; trimesh counts them from the end of the whole file.
- `check_ply_counts` refuses an ASCII PLY whose body holds fewer lines than its header declares.
- `texture_failures` collects trimesh's messages about textures it could not decode (it logs them at
  debug level and goes on untextured).
"""

from __future__ import annotations

import logging
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from trimesh.resolvers import FilePathResolver

MAX_ASSET_BYTES = 2**30
"""Largest file a mesh may reference (1 GiB: more than a 13000 x 13000 photo texture as PNG)."""
MAP_OPTIONS = {"-blendu": 1, "-blendv": 1, "-boost": 1, "-mm": 2, "-o": 3, "-s": 3, "-t": 3, "-texres": 1,
               "-clamp": 1, "-bm": 1, "-imfchan": 1, "-type": 1, "-cc": 1}
"""The MTL texture-map options and their most arguments (`-o`, `-s`, `-t` take one to three numbers)."""
_VARIABLE = ("-o", "-s", "-t")
_FACE_LINE = re.compile(r"^[ \t]*f[ \t][^\n]*-[0-9]", re.MULTILINE)


class GuardedResolver(FilePathResolver):
    """trimesh's resolver of the mesh's folder, opening regular files only, of bounded size.

    What it refused (`refused`) or did not find (`missing`) is kept, since trimesh swallows the error."""

    def __init__(self, source: str | Path) -> None:
        super().__init__(str(source))
        self.refused: list[str] = []
        self.missing: list[str] = []

    def get(self, name: str) -> bytes:
        """The bytes of `name` (an MTL with its map options dropped); OSError or ValueError otherwise."""
        path = self.absolute(name)  # a ValueError for a name leaving the folder
        if not path.exists():
            self.missing.append(name)
            raise FileNotFoundError(f"{name} not found")
        if not path.is_file():
            self.refused.append(f"it names {name!r}, which is not a regular file (a FIFO, device or "
                                f"folder); name a file")
            raise ValueError(self.refused[-1])
        size = path.stat().st_size
        if size > MAX_ASSET_BYTES:
            self.refused.append(f"it names {name!r} of {size} bytes, more than the {MAX_ASSET_BYTES} a "
                                f"referenced file may have")
            raise ValueError(self.refused[-1])
        with open(path, "rb") as handle:
            data = handle.read(MAX_ASSET_BYTES + 1)
        return strip_map_options(data) if path.suffix.lower() == ".mtl" else data


def strip_map_options(mtl: bytes) -> bytes:
    """An MTL with the options dropped from its `map_Kd` lines (`map_Kd -s 2 2 1 tex.png` -> `map_Kd
    tex.png`).

    Example:
        >>> strip_map_options(b"map_Kd -s 2 2 1 -o 0.5 0.5 0 -clamp on my tex.png")
        b'map_Kd my tex.png'
    """
    lines = mtl.decode("utf-8", errors="surrogateescape").split("\n")
    for i, line in enumerate(lines):
        words = line.split()
        if len(words) > 1 and words[0].lower() == "map_kd" and words[1] in MAP_OPTIONS:
            lines[i] = f"{words[0]} {_file_name(line)}"
    return "\n".join(lines).encode("utf-8", errors="surrogateescape")


def _file_name(line: str) -> str:
    """The file name of a `map_Kd` line: what follows the statement and its options, spaces kept."""
    tokens = list(re.finditer(r"\S+", line))
    i = 1
    while i < len(tokens) and tokens[i].group() in MAP_OPTIONS:
        option, i = tokens[i].group(), i + 1
        for _ in range(MAP_OPTIONS[option]):
            if i >= len(tokens) - 1 or (option in _VARIABLE and not _is_number(tokens[i].group())):
                break
            i += 1
    return line[tokens[min(i, len(tokens) - 1)].start():].strip()


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def resolve_obj_indices(text: str) -> str:
    """OBJ text whose negative face indices are made absolute against the `v`, `vt`, `vn` lines so far.

    Raises:
        ValueError: an index reaching before the first vertex, naming its line.
    Example:
        >>> resolve_obj_indices("v 0 0 0\\nv 1 0 0\\nv 0 1 0\\nf -3 -2 -1\\nv 0 0 1\\nf -4 -3 -1\\n")
        'v 0 0 0\\nv 1 0 0\\nv 0 1 0\\nf 1 2 3\\nv 0 0 1\\nf 1 2 4\\n'
    """
    if not _FACE_LINE.search(text):
        return text
    counts = {"v": 0, "vt": 0, "vn": 0}
    lines = text.replace("\\\n", "").split("\n")
    for number, line in enumerate(lines, 1):
        words = line.split()
        if words and words[0] in counts:
            counts[words[0]] += 1
        elif words and words[0] == "f":
            lines[number - 1] = "f " + " ".join(_absolute(w, counts, number) for w in words[1:])
    return "\n".join(lines)


def _absolute(word: str, counts: dict[str, int], line: int) -> str:
    parts = word.split("/")
    for k, (part, kind) in enumerate(zip(parts, ("v", "vt", "vn"))):
        if part.startswith("-") and part[1:].isdigit():
            index = counts[kind] + int(part) + 1
            if index < 1:
                raise ValueError(f"line {line}: face index {part} reaches before the first {kind} line")
            parts[k] = str(index)
    return "/".join(parts)


def check_ply_counts(path: Path) -> None:
    """Refuse (ValueError) an ASCII PLY whose body holds fewer lines than its elements declare (a binary
    PLY's short body trimesh refuses itself)."""
    with open(path, "rb") as handle:
        if handle.readline().strip() != b"ply":
            return
        declared, ascii_format = 0, False
        for line in handle:
            words = line.split()
            if words[:2] == [b"format", b"ascii"]:
                ascii_format = True
            elif words[:1] == [b"element"] and len(words) == 3 and words[2].isdigit():
                declared += int(words[2])
            elif words[:1] == [b"end_header"]:
                break
        if not ascii_format:
            return
        body = sum(1 for line in handle if line.strip())
    if body < declared:
        raise ValueError(f"its header declares {declared} element lines (vertices, faces, ...) but its body "
                         f"holds {body}: the file is truncated or its counts are wrong")


class _TextureLog(logging.Handler):
    """Keeps trimesh's log messages about images and textures, with the error behind each."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        if "image" in text.lower() or "texture" in text.lower():
            error = record.exc_info[1] if record.exc_info else None
            self.messages.append(f"{text.rstrip('!')}: {type(error).__name__}: {error}" if error else text)


@contextmanager
def texture_failures() -> Iterator[list[str]]:
    """Within the block, the messages trimesh logs about textures it could not use (it goes on without
    them, and only logs at debug level)."""
    logger, handler = logging.getLogger("trimesh"), _TextureLog()
    level = logger.level
    logger.addHandler(handler)
    logger.setLevel(logging.DEBUG)
    try:
        yield handler.messages
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)
