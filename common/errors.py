"""I/O errors in one line: what failed (the OS's words and the errno's name) and the path it failed at.

The atomic writers (`common.io`) turn an OSError raised while an output is written (a full disk, a
quota, an I/O error) into a `WriteError` naming the output's own path (not its temporary name), and the
CLI prints it as one line: `nbv scan: error: no space left on device (ENOSPC) writing OUT/images/0003.png`.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path


class WriteError(OSError):
    """An OSError raised while writing an output, naming the output's path."""

    def __str__(self) -> str:
        return describe(self)


def describe(err: OSError) -> str:
    """One line for an OSError: `no space left on device (ENOSPC) writing PATH` (`at PATH` when it is not
    a WriteError); its own message when it carries no errno (a message written for the user)."""
    if err.errno is None:
        return str(err)
    verb = "writing" if isinstance(err, WriteError) else "at"
    what = (err.strerror or os.strerror(err.errno)).strip()
    line = f"{what[:1].lower()}{what[1:]} ({errno.errorcode.get(err.errno, err.errno)})"
    return f"{line} {verb} {err.filename}" if err.filename else line


def as_write_error(err: OSError, tmp: Path, out: Path) -> OSError:
    """`err` as a WriteError naming the path under `out` that was being written as `tmp` (or `out` itself
    when it names no file); `err` unchanged when it has no errno, or names a file outside `tmp`
    (an input read inside the block)."""
    if err.errno is None:
        return err
    name = err.filename2 if err.filename2 is not None else err.filename
    if name is None:
        path = out
    elif _under(Path(os.fsdecode(name)), tmp):
        path = out / Path(os.fsdecode(name)).relative_to(tmp)
    else:
        return err
    return WriteError(err.errno, err.strerror or os.strerror(err.errno), str(path))


def _under(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents
