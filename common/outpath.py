"""`--out` itself, checked before any work: not empty, not too long for the file system, not a symlink to
nothing (issue 28; the folder's content is `common.io.check_output_folder`'s concern)."""

from __future__ import annotations

import os
from pathlib import Path

NAME_ROOM = 32
"""Bytes an output's name leaves free for the names written beside it (its temporary folder is
`.NAME.tmp-PID-` and eight random characters)."""


def check_out_path(out: str | Path) -> None:
    """Refuse (ValueError naming it) an output path that is empty, too long for the file system
    (ENAMETOOLONG) or a symlink to nothing."""
    text = os.fspath(out)
    if not text.strip():
        raise ValueError("--out is empty: name the output folder (e.g. --out runs/scan1)")
    parts = Path(text).parts
    name_max = _pathconf(Path(text), "PC_NAME_MAX", 255)
    for i, part in enumerate(parts):
        limit = name_max - (NAME_ROOM if i == len(parts) - 1 else 0)
        if len(os.fsencode(part)) > limit:
            raise ValueError(f"output {_short(text)}: file name too long (ENAMETOOLONG): a part of "
                             f"{len(os.fsencode(part))} bytes, at most {limit}; use a shorter name")
    limit = _pathconf(Path(text), "PC_PATH_MAX", 4096) - name_max
    if len(os.fsencode(os.path.abspath(text))) > limit:
        raise ValueError(f"output {_short(text)}: path too long (ENAMETOOLONG): "
                         f"{len(os.fsencode(os.path.abspath(text)))} bytes, at most {limit}")
    if os.path.islink(text) and not os.path.exists(text):
        raise FileNotFoundError(f"output {text} is a symlink to {os.readlink(text)}, which does not exist "
                                "(remove the link or create its target)")


def _pathconf(path: Path, name: str, default: int) -> int:
    """`os.pathconf` of the nearest existing folder holding `path`."""
    folder = Path(os.path.abspath(path)).parent
    while not os.path.isdir(folder) and folder != folder.parent:  # os.path: no error on a long name
        folder = folder.parent
    try:
        return os.pathconf(folder, name)
    except (OSError, ValueError):
        return default


def _short(text: str) -> str:
    return text if len(text) <= 80 else f"{text[:60]}...({len(text)} characters)"
