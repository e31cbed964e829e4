"""Structure from motion as a check of a view set: COLMAP (pycolmap, CPU) with the known intrinsics,
scored against the true poses after a similarity fit (`nbv sfm`; docs/sfm.md)."""

from nbv.sfm.align import Similarity, umeyama
from nbv.sfm.config import SfmConfig, SfmSettings

__all__ = ["SfmConfig", "SfmSettings", "Similarity", "umeyama"]
