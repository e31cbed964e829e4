"""How views are rendered: the render config every command that renders nests (one declaration)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from tyro.conf import Suppress

from render.variant import Variant

MAX_SPP = 65_536
"""Most samples per pixel (Mitsuba's samplers refuse counts near 2^32; 64k is far past converged)."""


@dataclass(frozen=True)
class RenderSettings:
    """How RGB images are rendered (depth always uses one exact ray per pixel)."""

    spp: int = 16
    """Samples per pixel of the RGB pass, in [1, 65536]."""
    max_depth: int = 4
    """Longest light path (path integrator): 2 = direct light only."""
    integrator: Literal["path", "direct"] = "path"
    """Mitsuba integrator of the RGB pass."""
    variant: Variant | None = None
    """Mitsuba variant; default: $NBV_VARIANT, else the fastest available (chosen per process)."""
    seed: Suppress[int] = 0
    """Base seed; view i of a scan is rendered with seed `seed * 1_000_003 + i`. Set from each command's
    own --seed, so it is no flag of its own."""

    def __post_init__(self) -> None:
        if not 1 <= self.spp <= MAX_SPP:
            raise ValueError(f"render spp must lie in [1, {MAX_SPP}], got {self.spp}")
        if self.max_depth < 1 and self.max_depth != -1:
            raise ValueError(f"render max_depth must be >= 1 (or -1), got {self.max_depth}")
        if self.integrator not in ("path", "direct"):
            raise ValueError(f"render integrator must be 'path' or 'direct', got {self.integrator!r}")

    def view_seed(self, index: int) -> int:
        """The per-view seed of view `index` (Mitsuba uses seed 0 unless told)."""
        return (self.seed * 1_000_003 + index) % (2**31)
