"""The up axis of a mesh file: the one name the scene spec and the normaliser share.

Its own module so that `scenes.spec` (light, read by the command line) and
`scenes.normalise` (mesh code) both take it from below them.
"""

from __future__ import annotations

from typing import Literal, get_args

UpAxis = Literal["z", "y"]
"""The up axis of a mesh file; 'y' (glTF, many DCC exports) is turned to z up."""
UP_AXES: tuple[str, ...] = get_args(UpAxis)
"""Up axes a mesh file may use."""
