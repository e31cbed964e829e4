"""Where a result came from: the commit that produced it, and its config as a record and back.

Every single-run output (`plan.json`, `metrics.json`, `refine.json`, `reconstruction.json`,
`sweep.json`, a scan's `transforms.json` under `nbv`) carries one `run_record`: `commit`, `command`
and the whole `config`, and `nbv COMMAND --config FILE` re-runs it (`recorded_config`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
import subprocess
import types
import typing
from pathlib import Path
from typing import Any, TypeVar

T = TypeVar("T")


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], capture_output=True, text=True, check=True).stdout.strip()


def config_record(config: Any, omit: tuple[str, ...] = ()) -> dict:
    """A config dataclass as JSON-compatible nested dicts (tuples as lists, paths as strings), without its
    top-level fields `omit` (e.g. `executor`, which changes no number)."""
    record = json.loads(json.dumps(dataclasses.asdict(config), default=str))
    return {k: v for k, v in record.items() if k not in omit}


def config_from_record(cls: type[T], record: dict) -> T:
    """The config dataclass `cls` rebuilt from `config_record`'s output (the inverse, nested included).

    Keys the record lacks take the field's default; unknown keys are an error naming them. A class with
    an `upgrade_record(record) -> record` static method first brings an older layout up to date.

    Example:
        >>> Run = dataclasses.make_dataclass("Run", [("sizes", tuple[int, ...]), ("out", Path | None)])
        >>> config_from_record(Run, {"sizes": [2, 3], "out": "run"})
        Run(sizes=(2, 3), out=PosixPath('run'))
    """
    if not isinstance(record, dict):
        raise ValueError(f"a {cls.__name__} record must be a JSON object, got {type(record).__name__}")
    upgrade = getattr(cls, "upgrade_record", None)
    if upgrade is not None:
        record = upgrade(record)
    hints = typing.get_type_hints(cls, include_extras=False)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(record) - set(fields))
    if unknown:
        raise ValueError(f"{cls.__name__} has no field(s) {', '.join(unknown)}")
    for name, value in record.items():
        _check_choice(cls, name, hints[name], value)
    return cls(**{name: _value(hints[name], value) for name, value in record.items()})


def _check_choice(cls: type, name: str, tp: Any, value: Any) -> None:
    """Refuse a value outside a `Literal` field's choices (a record is not checked by tyro's parser)."""
    if typing.get_origin(tp) is typing.Literal and value not in typing.get_args(tp):
        choices = ", ".join(repr(c) for c in typing.get_args(tp))
        raise ValueError(f"{cls.__name__} field {name} is {value!r}, not one of {choices}")


def _value(tp: Any, value: Any) -> Any:
    if value is None:
        return None
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        options = [a for a in typing.get_args(tp) if a is not type(None)]
        tp = options[0] if len(options) == 1 else _recorded_option(options, value)
    if dataclasses.is_dataclass(tp):
        return config_from_record(tp, value)
    if typing.get_origin(tp) is tuple and isinstance(value, list):
        args = typing.get_args(tp)
        item = args[0] if args else Any
        return tuple(_value(item, v) for v in value)
    if tp is Path:
        return Path(value)
    return value


def _recorded_option(options: list[Any], value: Any) -> Any:
    """The dataclass of a union (e.g. a scan plan) whose fields are exactly the record's keys, else Any."""
    if isinstance(value, dict):
        for option in filter(dataclasses.is_dataclass, options):
            if {f.name for f in dataclasses.fields(option)} == value.keys():
                return option
    return Any


def run_record(command: str, config: Any) -> dict[str, Any]:
    """The provenance of one run, in the one style of every single-run output: the `commit`, the
    `command` that ran (e.g. "nbv plan") and its whole `config` (`config_record`)."""
    return {"commit": git_commit(), "command": command, "config": config_record(config)}


def recorded_config(cls: type[T], path: str | Path, command: str) -> T:
    """The config `cls` of the run record in the JSON file `path` (its `config`, or a dataset's
    `nbv.config`), refused (ValueError naming the file) when another command wrote it."""
    try:
        doc = json.loads(Path(path).read_text())
    except (OSError, ValueError) as err:
        raise ValueError(f"--config {path}: not a readable JSON file ({err})") from err
    record = doc.get("nbv", {}) if isinstance(doc, dict) and "config" not in doc else doc
    if not isinstance(record, dict) or not isinstance(record.get("config"), dict):
        raise ValueError(f"--config {path}: no run record (a `config` object) in it")
    if record.get("command", command) != command:
        raise ValueError(f"--config {path}: recorded by `{record['command']}`, not `{command}`")
    try:
        return config_from_record(cls, record["config"])
    except TypeError as err:
        raise ValueError(f"--config {path}: {err}") from err


ELSEWHERE = "ELSEWHERE"
"""What stands, in a committed record, for the folders above a path outside the working directory."""
_ABSOLUTE = re.compile(r"(?<![\w./])/(?!/)[^\s:=,'\"]+")


def portable_path(path: str | Path, root: Path | None = None) -> str:
    """`path` as a committed record may hold it: relative to `root` (default: the working directory) when
    under it, else its last two parts under `ELSEWHERE` (no machine's folders in a record).

    Example:
        >>> portable_path("/home/ann/runs/r1/policy.pt", Path("/srv/nbv"))
        'ELSEWHERE/r1/policy.pt'
    """
    root = (root or Path.cwd()).resolve()
    absolute = Path(path).resolve()
    if absolute.is_relative_to(root):
        return absolute.relative_to(root).as_posix() or "."
    return "/".join((ELSEWHERE, *absolute.parts[1:][-2:]))


def portable_text(text: str, root: Path | None = None) -> str:
    """`text` (a command line, an argument such as `NAME=PATH` or `policy:PATH`) with every absolute path
    in it made portable (`portable_path`); relative paths and URLs are left as they are."""
    return _ABSOLUTE.sub(lambda match: portable_path(match.group(), root), text)


def portable_record(record: Any, root: Path | None = None) -> Any:
    """A JSON-compatible record with `portable_text` applied to every string in it."""
    if isinstance(record, str):
        return portable_text(record, root)
    if isinstance(record, dict):
        return {key: portable_record(value, root) for key, value in record.items()}
    if isinstance(record, list):
        return [portable_record(value, root) for value in record]
    return record


RESULTS = "paper_results"
"""Where committed results live: their own changes (a run writing them) do not make the code dirty."""


def git_commit() -> str:
    """Short hash of the checked-out commit (with '+dirty' for uncommitted changes to tracked files outside
    `RESULTS`), or 'unknown'."""
    try:
        dirty = "+dirty" if _git("status", "--porcelain", "-uno", "--", ".", f":(exclude){RESULTS}") else ""
        return _git("rev-parse", "--short", "HEAD") + dirty
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def run_cache(kind: str, config: Any, unkeyed: tuple[str, ...] = ()) -> Path:
    """A cache folder for the work units of a study: `$NBV_CACHE_DIR/<kind>/<key>`, keyed by the config's
    fields (but `unkeyed`, those that only choose which units run) and the commit, so an interrupted run
    resumes and a run at another commit measures afresh."""
    from common.io import cache_dir

    record = [config_record(config, unkeyed), git_commit()]
    key = hashlib.sha1(json.dumps(record, sort_keys=True, default=str).encode()).hexdigest()
    return cache_dir() / kind / key[:16]
