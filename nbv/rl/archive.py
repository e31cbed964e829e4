"""Checks of a `torch.save` file before and after `torch.load`: its zip archive, and its tensors' checksum.

Torch's zip reader checks neither the CRCs of the entries nor how far they inflate, so a file with
zeroed weight bytes loads as other weights, and a small zip bomb takes gigabytes before it is refused.
`check_archive` reads the zip's central directory first (no entry is inflated): every entry must be
stored uncompressed, as `torch.save` writes them, within the file's size, and every entry's CRC must
match. `tensor_checksum` is the SHA-256 of every tensor of a saved state (name, dtype, shape, bytes),
stored in the file beside them and compared once it is loaded.
"""

from __future__ import annotations

import hashlib
import zipfile
from pathlib import Path
from typing import Any

import torch

CHECKSUM_KEY = "checksum"
"""Where a saved state keeps `tensor_checksum` of the rest of it."""


class ArchiveError(ValueError):
    """A `torch.save` zip archive that is corrupt, compressed, or larger inflated than on disk."""


def check_archive(path: Path) -> None:
    """Refuse (ArchiveError) a zip archive whose entries are compressed, inflate beyond the file's size,
    or fail their CRC; a file that is not a zip archive is left to `torch.load` to judge."""
    if not zipfile.is_zipfile(path):
        return
    try:
        with zipfile.ZipFile(path) as archive:
            entries = archive.infolist()
            inflated = sum(entry.file_size for entry in entries)
            compressed = [e.filename for e in entries if e.compress_type != zipfile.ZIP_STORED]
            if compressed or inflated > path.stat().st_size:
                raise ArchiveError(f"its zip entries inflate to {inflated} bytes from {path.stat().st_size} "
                                   f"on disk ({len(compressed)} compressed; torch.save stores them "
                                   f"uncompressed): refused before reading, as a zip bomb would be")
            for entry in entries:
                _check_crc(archive, entry)
    except (zipfile.BadZipFile, OSError, EOFError) as err:
        raise ArchiveError(f"its zip archive is corrupt ({err})") from err


def _check_crc(archive: zipfile.ZipFile, entry: zipfile.ZipInfo) -> None:
    """Refuse an entry whose bytes do not match its CRC (0: written without CRCs, nothing to check)."""
    if entry.CRC == 0:
        return
    with archive.open(entry) as handle:
        while handle.read(2**20):  # zipfile raises BadZipFile at the end when the CRC differs
            pass


def tensor_checksum(state: Any) -> str:
    """SHA-256 over every tensor in a nested state (dict keys sorted, lists in order), each hashed with
    its path, dtype and shape; the `CHECKSUM_KEY` entry itself left out."""
    digest = hashlib.sha256()
    _hash_into(digest, state, "")
    return digest.hexdigest()


def _hash_into(digest: Any, node: Any, where: str) -> None:
    if isinstance(node, torch.Tensor):
        data = node.detach().cpu().contiguous()
        digest.update(f"{where}:{data.dtype}:{tuple(data.shape)}\0".encode())
        digest.update(data.reshape(-1).view(torch.uint8).numpy())  # a buffer: hashed without a copy
    elif isinstance(node, dict):
        for key in sorted(node, key=str):
            if not (where == "" and key == CHECKSUM_KEY):
                _hash_into(digest, node[key], f"{where}/{key}")
    elif isinstance(node, (list, tuple)):
        for i, item in enumerate(node):
            _hash_into(digest, item, f"{where}[{i}]")


def nonfinite_weights(weights: dict[str, Any]) -> list[str]:
    """The names of the floating-point tensors of a state dict that hold a NaN or an infinity."""
    return [name for name, value in weights.items() if isinstance(value, torch.Tensor)
            and value.is_floating_point() and not bool(torch.isfinite(value).all())]
