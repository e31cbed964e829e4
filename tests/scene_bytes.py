"""A test helper: one digest of everything a built scene is made of (geometry, UVs, texture files)."""

from __future__ import annotations

import hashlib


def scene_bytes_digest(scene) -> str:
    """SHA-256 (hex) over each part's vertices, faces, UVs and texture file, in part order."""
    h = hashlib.sha256()
    for p in scene.parts:
        h.update(p.vertices.tobytes() + p.faces.tobytes() + (p.uv.tobytes() if p.uv is not None else b""))
        if p.material.texture is not None:
            h.update(p.material.texture.read_bytes())
    return h.hexdigest()
