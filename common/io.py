"""Atomic file writes, JSON, Markdown tables and the cache folder: one implementation of each.

A file is written under a temporary name beside its destination (the name
holds the process id, so two runs never share one) and renamed into place,
so a reader sees the old file or the new one, never half of one.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write `path`'s content to; renamed onto `path` when the block succeeds.

    The temporary name keeps the suffix, so writers that pick a format by suffix (PIL, trimesh) work.

    Example:
        >>> import tempfile
        >>> folder = Path(tempfile.mkdtemp())
        >>> with atomic_path(folder / "a.txt") as tmp:
        ...     _ = tmp.write_text("hello")
        >>> (folder / "a.txt").read_text(), sorted(p.name for p in folder.iterdir())
        ('hello', ['a.txt'])
    """
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}")
    try:
        yield tmp
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> Path:
    """Write `text` to `path` atomically; returns `path`."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def write_json(path: str | Path, doc: Any) -> Path:
    """Write `doc` as indented JSON atomically; returns `path`."""
    return write_text(path, json.dumps(doc, indent=2))


def cache_dir() -> Path:
    """The cache root: `$NBV_CACHE_DIR` if set and not empty, else `~/.cache/nbv`; created on demand."""
    root = Path(os.environ.get("NBV_CACHE_DIR") or Path.home() / ".cache" / "nbv")
    root.mkdir(parents=True, exist_ok=True)
    return root


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """A GitHub Markdown table (cells as `str`), one line per row, ending in a newline.

    Example:
        >>> print(markdown_table(["a", "b"], [[1, 2.5]]), end="")
        | a | b |
        |---|---|
        | 1 | 2.5 |
    """
    lines = ["| " + " | ".join(map(str, header)) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(map(str, row)) + " |" for row in rows]
    return "\n".join(lines) + "\n"
