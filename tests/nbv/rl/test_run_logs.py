"""A run's logs cut back to its checkpoint on resume: rows after it, torn rows, lost headers, repeats (a
real 0-byte log left by a SIGKILL: test_kill_resume)."""

from __future__ import annotations

import csv

from nbv.rl.run_logs import trim_log, validation_fields

FIELDS = ("frames", "a", "b")


def read(path) -> tuple[list[str], list[list[str]]]:
    """The header and rows of a CSV file, read with the csv module."""
    with open(path, newline="") as file:
        rows = list(csv.reader(file))
    return rows[0], rows[1:]


def test_rows_after_the_checkpoint_and_a_torn_last_row_go(tmp_path):
    path = tmp_path / "metrics.csv"
    path.write_text("frames,a,b\n2,x,y\n4,x,y\n6,x,y\n8,x")  # 6 was logged after the checkpoint at 4
    trim_log(path, 4, FIELDS)
    assert read(path) == (["frames", "a", "b"], [["2", "x", "y"], ["4", "x", "y"]])
    path.write_text("frames,a,b\n2,x,y\n4,x,y\n6,x,y\n8,x")
    trim_log(path, 8, FIELDS)  # the torn row goes even when the checkpoint is past it
    assert read(path)[1] == [["2", "x", "y"], ["4", "x", "y"], ["6", "x", "y"]]


def test_an_empty_or_headerless_log_gets_its_header_back(tmp_path):
    path = tmp_path / "metrics.csv"
    path.write_bytes(b"")  # killed before the header left Python's buffer
    trim_log(path, 0, FIELDS)
    assert read(path) == (["frames", "a", "b"], [])
    path.write_text("2,x,y\n4,x,y\n3,bad\n")  # rows appended to that empty file by a rerun
    trim_log(path, 4, FIELDS)
    assert read(path) == (["frames", "a", "b"], [["2", "x", "y"], ["4", "x", "y"]])
    trim_log(tmp_path / "missing.csv", 4, FIELDS)
    assert not (tmp_path / "missing.csv").exists()


def test_rows_logged_twice_by_an_earlier_resume_are_kept_once(tmp_path):
    path = tmp_path / "validation.csv"
    header = validation_fields(["random:6"])
    rows = [[str(f), "50.0", "50.0", "2", "12.5"] for f in (2, 4, 6, 4, 6, 8)]
    path.write_text("\n".join(",".join(r) for r in [header, *rows]) + "\n")
    trim_log(path, 8, header)
    assert read(path) == (header, [[str(f), "50.0", "50.0", "2", "12.5"] for f in (2, 4, 6, 8)])


def test_a_log_from_before_the_metres_column_gets_it_and_keeps_its_rows(tmp_path):
    path = tmp_path / "validation.csv"
    header = validation_fields(["random:6"])
    old = [header[:-1], ["2", "50.0", "50.0", "2"], ["4", "60.0", "60.0", "4"]]  # no metres yet
    path.write_text("\n".join(",".join(r) for r in [*old, ["6", "55.0", "55.0", "4", "12.5"]]) + "\n")
    trim_log(path, 6, header)  # a resumed run appended a row with metres
    assert read(path) == (header, [old[1], old[2], ["6", "55.0", "55.0", "4", "12.5"]])
