"""A run's CSV logs cut back to its checkpoint when it resumes, so they always agree with it.

`metrics.csv` gets a row per batch and `validation.csv` one per validated
checkpoint; both reach the disk before `checkpoint.pt` is replaced. A run
killed after that flush but before its checkpoint, or before its first one,
leaves rows its checkpoint does not know, a torn last row, or an empty
`metrics.csv` whose header was still in Python's buffer. A resumed run then
logged those frames twice, or could not read its own log (`no field of name
frames`). `trim_log` keeps the header and the rows up to the checkpoint's
frame count (complete ones, frames rising), gives an empty or headerless log
its header back, and rewrites the file atomically; the run then appends the
rest, so its logs end where an uninterrupted run's do.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path

from common.io import atomic_path


def validation_fields(scenes: Sequence[str]) -> list[str]:
    """The header of `validation.csv`: frames, the score of each validation building, mean, best_frames,
    and the metres the actor flew per episode (last: logs written before it have rows one shorter)."""
    return ["frames", *scenes, "mean", "best_frames", "metres"]


def trim_log(path: Path, frames: int, fields: Sequence[str]) -> None:
    """Cut the CSV log `path` (first column `frames`) back to the rows of a checkpoint at `frames`; a log
    without its header gets `fields` (its rows kept if they have as many columns), and one whose header
    is the start of `fields` (written before columns were added) gets `fields`, its shorter rows kept.
    No file: nothing."""
    if not path.is_file():
        return
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines(keepends=True)
    if lines and not lines[-1].endswith("\n"):
        lines = lines[:-1]  # torn by a kill mid-write
    rows = list(csv.reader(lines))
    header = rows.pop(0) if rows and rows[0][:1] == ["frames"] else list(fields)
    widths = {len(header)}
    if len(header) < len(fields) and header == list(fields[:len(header)]):
        header, widths = list(fields), widths | {len(fields)}  # a log from before columns were added
    kept = rows_until(rows, widths, frames)
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as file:
        log = csv.writer(file)
        log.writerow(header)
        log.writerows(kept)


def rows_until(rows: list[list[str]], widths: set[int], frames: int) -> list[list[str]]:
    """The rows of one of `widths` columns whose frame count rises and stays at most `frames` (a repeated
    or malformed row is dropped: what a resume before this fix logged twice)."""
    kept, last = [], 0
    for row in rows:
        try:
            at = int(row[0]) if len(row) in widths else None
        except ValueError:
            at = None
        if at is not None and last < at <= frames:
            kept.append(row)
            last = at
    return kept
