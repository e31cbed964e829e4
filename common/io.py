"""Atomic file writes, JSON, Markdown tables and the cache folder: one implementation of each.

A file is written under a temporary name beside its destination (the name
holds the process id, so two runs never share one) and renamed into place,
so a reader sees the old file or the new one, never half of one. A command's
output folder is written the same way (`atomic_folder`), and the temporary
folders of a run that died are cleaned up by the next run writing that folder.
One run writes an output at a time: its lock (`common.locks`) is held from the
up-front check to the swap, and a run without overwrite never replaces an output
that appeared meanwhile. An OSError while writing names the output's path, not the
temporary one (`common.errors.WriteError`); a cache write that fails only warns (`common.cache`).
"""

from __future__ import annotations

import ctypes
import errno
import json
import os
import re
import shutil
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, NoReturn

from common.errors import as_write_error, describe
from common.locks import OutputBusy, claim, lock_file, release, remove_if_free
from common.outpath import check_out_path


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
    except OSError as err:
        _reraise_as_write_error(err, tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _reraise_as_write_error(err: OSError, tmp: Path, out: Path) -> NoReturn:
    """Raise `err` as a WriteError naming the path under `out` written as `tmp` (`common.errors`)."""
    named = as_write_error(err, tmp, out)
    if named is err:
        raise err
    raise named from err


def current_umask() -> int:
    """The process umask (read by setting it and putting it back)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def output_target(out: str | Path) -> Path:
    """Where `out` is written: its target when `out` is a symlink (the link is kept), else `out`."""
    out = Path(out)
    return Path(os.path.realpath(out)) if out.is_symlink() else out


def check_output_folder(out: Path, overwrite: bool, outputs: tuple[str, ...] | None = None) -> None:
    """Fail early, naming the folder, if `out` cannot be written or would lose existing data; then hold
    its lock (`common.locks`: a second run on `out` fails at once, naming this one) until the swap.

    `outputs`: the names the command writes into `out` (other entries are kept); None: the whole folder.
    """
    check_out_path(out)
    out, target = Path(out), output_target(out)
    cwd = Path.cwd().resolve()
    if target.resolve() == cwd or target.resolve() in cwd.parents:
        raise ValueError(f"output folder {out} is the current folder or holds it; name a new folder "
                         f"(e.g. --out {out / 'run'})")
    if target.exists() and not target.is_dir():
        raise FileExistsError(f"output {out} exists and is not a folder")
    parent = target.parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise FileNotFoundError(f"output folder {out} cannot be made: {parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise PermissionError(f"output folder {out} is not writable (no write access to {parent})")
    try:
        claim(target, wait=True if in_cache(target) else None)  # a cache entry: its writer's result will do
    except OutputBusy:
        raise
    except OSError as err:  # e.g. /proc passes the checks above but takes no lock file
        raise PermissionError(f"output folder {out} cannot be made: {describe(err)}") from None
    recover_stale(target)
    try:
        check_not_replaced(out, target, overwrite, outputs)
    except FileExistsError:
        release(target)
        raise


def check_not_replaced(out: Path, target: Path, overwrite: bool, outputs: tuple[str, ...] | None,
                       late: bool = False) -> None:
    """Without `overwrite`, FileExistsError naming `out` when writing it would replace output (`late`:
    output that appeared while this run ran)."""
    when = " (it appeared while this run ran; nothing was replaced)" if late else ""
    if overwrite:
        return
    if outputs is None:
        if target.is_dir() and any(target.iterdir()):
            raise FileExistsError(f"output folder {out} exists and is not empty{when} (use --overwrite)")
    elif existing := [name for name in outputs if (target / name).exists()]:
        raise FileExistsError(f"{out} already holds {', '.join(existing)}{when} (use --overwrite)")


def check_separate(out: str | Path, source: str | Path, may_hold: bool = False) -> None:
    """Refuse (ValueError naming `out`) an output folder that is or lies in the input folder `source`,
    or holds it unless `may_hold` (when the output replaces only its own files)."""
    out_path, src_path = Path(out).resolve(), Path(source).resolve()
    if out_path == src_path or src_path in out_path.parents:
        raise ValueError(f"out {out} must not be the input folder {source} or lie inside it")
    if out_path in src_path.parents and not may_hold:
        raise ValueError(f"out {out} holds the input folder {source}: replacing it would delete the input")


PF_EXITING = 0x4
"""The kernel's per-process flag of a process in exit (`/proc/PID/stat` field 9): set before the dying
process closes its files, so before a parent (a Ray raylet) can see its sockets close."""


def _pid_alive(pid: int) -> bool:
    """Whether process `pid` still runs: a killed worker still tearing down (PF_EXITING) or not yet reaped
    by its parent (a zombie, which signal 0 still reaches) is dead."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        state, flags = fields[0], int(fields[6])
    except (OSError, IndexError, ValueError):
        return True
    return state not in ("Z", "X") and not flags & PF_EXITING


def recover_stale(out: str | Path) -> None:
    """Clean up after dead runs that wrote `out`: remove their `.NAME.tmp-PID-*` folders, their lock file
    `.NAME.lock` and their `.NAME.old-PID` (the previous output moved aside for the swap), put back if
    `out` is missing."""
    out = Path(out)
    if not out.parent.is_dir():
        return
    pattern = re.compile(rf"\.{re.escape(out.name)}\.(tmp|old)-(\d+)(-.*)?")
    remove_if_free(lock_file(out))  # a SIGKILLed run's (the lock itself died with it)
    for entry in sorted(out.parent.iterdir(), key=lambda p: p.name):
        match = pattern.fullmatch(entry.name)
        if match is None or _pid_alive(int(match[2])):
            continue
        if match[1] == "old" and not out.exists():
            entry.rename(out)
        elif entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry, ignore_errors=True)
        else:
            entry.unlink(missing_ok=True)


def _renameat2(a: Path, b: Path, flag: int) -> bool:
    """Linux `renameat2` with `flag` (1: fail if `b` exists, 2: swap the two); False where unsupported."""
    renameat2 = getattr(ctypes.CDLL(None, use_errno=True), "renameat2", None)
    if renameat2 is None:
        return False
    at_fdcwd = -100
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), flag) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.EPERM):
        return False
    raise OSError(code, os.strerror(code), str(b))


def _exchange(a: Path, b: Path) -> bool:
    """Swap two existing paths in one step (Linux `renameat2` RENAME_EXCHANGE); False where unsupported."""
    return _renameat2(a, b, 2)


def replace_folder(src: Path, dst: Path, replace: bool = True) -> None:
    """Move the finished folder `src` onto `dst`: in one exchange where the OS offers it, else the old `dst`
    is moved aside, removed only once `src` is in place, and put back if the swap fails or is interrupted.
    Without `replace`, a `dst` that exists by then (not an empty folder) is left alone: FileExistsError."""
    if not replace and not dst.exists():
        try:
            if _renameat2(src, dst, 1):
                return
        except FileExistsError:
            raise FileExistsError(f"output folder {dst} appeared while this run ran; nothing was "
                                  "replaced (use --overwrite)") from None
    if dst.is_dir() and not dst.is_symlink() and _exchange(src, dst):
        shutil.rmtree(src, ignore_errors=True)  # src now holds the old output
        return
    old = dst.with_name(f".{dst.name}.old-{os.getpid()}") if dst.exists() else None
    done = False
    try:
        if old is not None:
            dst.rename(old)
        src.rename(dst)
        done = True
    finally:
        if old is not None and old.exists():
            if done:
                shutil.rmtree(old, ignore_errors=True)
            elif not dst.exists():
                old.rename(dst)


def _carry(src: Path, dst: Path, skip: tuple[str, ...]) -> None:
    """Hard-link (or copy) the entries of `src` not named in `skip` into the empty folder `dst`."""
    for entry in src.iterdir():
        if entry.name in skip:
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.copytree(entry, dst / entry.name, symlinks=True, copy_function=_link_or_copy)
        else:
            _link_or_copy(entry, dst / entry.name)


def _link_or_copy(src: str | Path, dst: str | Path) -> None:
    if Path(src).is_symlink():
        os.symlink(os.readlink(src), dst)
        return
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


@contextmanager
def atomic_folder(out: str | Path, overwrite: bool = False,
                  outputs: tuple[str, ...] | None = None) -> Iterator[Path]:
    """A temporary folder beside `out` to write the output into; swapped onto `out` in one rename when
    the block succeeds, removed (and `out` left as it was) when it fails or is interrupted.

    `outputs`: the names the command writes (other entries of `out` are carried into the new folder);
    None: the whole folder is the output. Refuses (FileExistsError) to replace output without `overwrite`.

    Example:
        >>> folder = Path(tempfile.mkdtemp())
        >>> with atomic_folder(folder / "run") as tmp:
        ...     _ = (tmp / "a.txt").write_text("hello")
        >>> sorted(p.name for p in (folder / "run").iterdir()), sorted(p.name for p in folder.iterdir())
        (['a.txt'], ['run'])
    """
    out = Path(out)
    check_output_folder(out, overwrite, outputs)
    target = output_target(out)
    try:
        with scratch_folder(target) as tmp:
            try:
                yield tmp
                check_not_replaced(out, target, overwrite, outputs, late=True)
                if outputs is not None and target.is_dir():  # at the swap: what is in `out` now is kept
                    _carry(target, tmp, (*outputs, *(p.name for p in tmp.iterdir())))
                replace_folder(tmp, target, replace=overwrite)
            except OSError as err:
                _reraise_as_write_error(err, tmp, out)
    finally:
        release(target)


@contextmanager
def scratch_folder(out: str | Path) -> Iterator[Path]:
    """A new empty folder beside `out`, named like `atomic_folder`'s (a dead run's is cleaned up), removed
    when the block ends. Where it cannot be made: FileNotFoundError or PermissionError naming `out`."""
    out = Path(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-{os.getpid()}-", dir=out.parent))
    except (FileNotFoundError, FileExistsError, NotADirectoryError) as err:
        raise FileNotFoundError(f"output folder {out} cannot be made: {err.strerror}") from None
    except OSError as err:
        raise PermissionError(f"output folder {out} cannot be made: {err.strerror}") from None
    try:
        tmp.chmod(0o777 & ~current_umask())  # mkdtemp makes 0700; outputs are shared like any folder
        yield tmp
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


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
    root = _cache_root()
    root.mkdir(parents=True, exist_ok=True)
    return root


def _cache_root() -> Path:
    return Path(os.environ.get("NBV_CACHE_DIR") or Path.home() / ".cache" / "nbv")


def in_cache(path: str | Path) -> bool:
    """Whether `path` lies in the cache root (`cache_dir`)."""
    return Path(os.path.realpath(_cache_root())) in Path(os.path.realpath(path)).parents


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
