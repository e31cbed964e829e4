"""A ternary occupancy grid (unknown / free / occupied) built from depth images, and its view gain.

The volumetric map of active reconstruction (Isler et al., "An Information Gain
Formulation for Active Volumetric 3D Reconstruction", ICRA 2016; Delmerico et
al., "A comparison of volumetric information gain metrics for active 3D object
reconstruction", Autonomous Robots 42, 2018), kept ternary instead of
probabilistic:

- `integrate`: every voxel a captured pixel's ray crosses before its hit becomes
  free; the voxel holding the hit becomes occupied. A pixel with depth 0 (no
  hit in range) carves free space through the whole grid; a NaN pixel (not measured: stereo that found
  no match, `nbv.recon.stereo`) casts no ray and marks nothing. Occupied wins over
  free, now and later: a ray grazing a voxel that holds surface seen elsewhere
  does not clear it (log-odds maps weigh the two; a ternary map must choose).
  With `votes`, the grid weighs them instead, one vote an image: each image adds a
  hit to the voxels its pixels hit and a pass to the other voxels its rays cross,
  and a voxel is occupied while its hits are at least its passes, else free. A
  false match of stereo (`nbv.recon.stereo`) marks a floater that the rays of
  later images through it clear; exact depth needs no vote.
- `gain`: the number of distinct unknown voxels a candidate camera's rays reach,
  each ray stopping at the first occupied voxel: the "unobserved voxel" gain of
  both papers with a hard visibility (free and unknown voxels let the ray on,
  occupied ones stop it), computed by ray casting the grid, rendering nothing.
  With `first` = k, a ray counts only the first k unknown voxels it reaches: at
  k = 1, the unknown voxels a view would see were unknown space opaque, i.e. where
  its rays would meet new surface (the "rear side" of unknown space counts once a
  ray, not once a voxel of its depth; Delmerico et al.'s occlusion-aware gain
  with visibility 1 for the first k unknown voxels and 0 behind).
- `frontier`: the unknown voxels beside free space (Yamauchi 1997), where a
  surface not yet measured can lie.
- `sides` and `sighted`: from which of `SIGHT_BINS` directions (`sight_bin`) each
  occupied voxel has been measured, and from which a candidate's rays would first
  meet one. An occupied voxel holds every face of the surface inside it, so the
  unknown-voxel gain cannot see that the underside of an eave or the inner face
  of a parapet was never in view once the voxel is known; a hit from a new
  direction can (the viewing directions per voxel of surface-coverage planners,
  e.g. Vasquez-Gomez et al., "Volumetric next-best-view planning for 3D object
  reconstruction with positioning error", IJARS 2014, kept here as 12 bins).
  With `steep_deg`, rays looking down more steeply than that take bins of their
  own (16 in all): a wall seen only from nearly overhead is seen at a grazing
  angle, where a photograph resolves little of it, and still counts as unmeasured
  from the side (round 35). With `sectors` = 8, the horizontal directions are
  eight 45-degree sectors instead of four quadrants (24 or 32 bins): a face seen
  40 degrees off its normal stays unmeasured straight on (round 45).

Depth is z-depth (docs/conventions.md, `render.renderer`): a pixel's ray has
direction (x, y, 1) in the camera frame (`render.camera.pixel_rays`), so its hit
lies at range depth * |(x, y, 1)| along the unit direction. Rays are walked by
sampling every half voxel between their entry into and exit from the grid's box
(a sample can skip the corner of a voxel the ray clips; the gain is a count of
voxels, not exact lengths). Vectorised NumPy, in chunks of rays.

Example: a wall 3.5 m in front of a one-pixel camera, in a row of four 1 m voxels.
    >>> grid = OccupancyGrid(np.zeros(3), np.array([4.0, 1.0, 1.0]), resolution=4)
    >>> K = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
    >>> c2w = np.array([[0, 0, 1, -1.0], [1, 0, 0, 0.5], [0, 1, 0, 0.5], [0, 0, 0, 1]])  # looks along +x
    >>> grid.integrate(np.array([[3.5]], np.float32), K, c2w)
    >>> grid.state[:, 0, 0].tolist()  # free, free, occupied, unknown
    [1, 1, 2, 0]
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from render.camera import pixel_rays
from render.viewpoint import validate_pose

UNKNOWN, FREE, OCCUPIED = 0, 1, 2
"""Voxel states."""
SIGHT_BINS, LEVEL_SIN = 12, np.sin(np.radians(10.0))
"""Directions a voxel is measured from: 4 horizontal quadrants, each looking up, level or down (a ray's
vertical part beyond `LEVEL_SIN` of its length, 10 degrees); with a steep band (`sight_bin`), 16."""
SECTORS = (4, 8)
"""How `sight_bin` may split the horizon: 4 quadrants or 8 sectors of 45 degrees."""
CHUNK_SAMPLES = 1 << 21
"""Ray samples held at once (a few arrays of 2M numbers)."""


def sight_bin(directions: np.ndarray, steep_deg: float = 0.0, sectors: int = 4) -> np.ndarray:
    """The bin (0 to `SIGHT_BINS` - 1) of each unit ray direction (..., 3): its horizontal quadrant (by the
    larger of |x| and |y| and its sign) times 3, plus 0 looking down, 1 level, 2 looking up. With
    `steep_deg` > 0, the quadrant times 4, plus 0 looking down more steeply than that, then 1, 2, 3 as above
    (16 bins). With `sectors` = 8, the quadrant is one of eight 45-degree sectors, the first centred on +x,
    counter-clockwise.

    >>> sight_bin(np.array([[1.0, 0, 0], [0, -0.9, 0.44], [-0.6, 0.5, -0.62]])).tolist()
    [4, 2, 6]
    >>> sight_bin(np.array([[1.0, 0, 0], [0.5, 0, -0.87], [0.87, 0, -0.5]]), steep_deg=45).tolist()
    [6, 4, 5]
    >>> sight_bin(np.array([[1.0, 0, 0], [0.6, 0.6, 0.53], [0.6, -0.8, 0]]), sectors=8).tolist()
    [1, 5, 22]
    """
    if sectors not in SECTORS:
        raise ValueError(f"sight bins split the horizon into 4 or 8 sectors, got {sectors}")
    x, y, z = directions[..., 0], directions[..., 1], directions[..., 2]
    if sectors == 4:
        quadrant = np.where(np.abs(x) >= np.abs(y), np.where(x >= 0, 1, 2), np.where(y >= 0, 3, 0))
    else:
        quadrant = np.round(np.arctan2(y, x) / (np.pi / 4)).astype(np.int64) % 8
    band = (z > -LEVEL_SIN).astype(np.int64) + (z > LEVEL_SIN)
    if not steep_deg:
        return 3 * quadrant + band
    return 4 * quadrant + band + (z >= -np.sin(np.radians(steep_deg)))


class OccupancyGrid:
    """Cubic voxels over an axis-aligned box, each unknown, free or occupied; all unknown at first.

    Args:
        lower: (3,) the box's lower corner, metres.
        upper: (3,) its upper corner; the grid reaches at least this far (whole voxels).
        resolution: voxels along the box's longest side.
        votes: weigh hits and passes, one vote an image (module docstring), instead of occupied winning.
        steep_deg: > 0, rays looking down more steeply than this many degrees are a direction of their own
            (`sight_bin`, `sight_bins` 16).
        sectors: the horizontal directions of `sight_bin`, 4 quadrants or 8 sectors.
    """

    def __init__(self, lower: np.ndarray, upper: np.ndarray, resolution: int, votes: bool = False,
                 steep_deg: float = 0.0, sectors: int = 4) -> None:
        self.lower = np.asarray(lower, dtype=np.float64)
        extent = np.asarray(upper, dtype=np.float64) - self.lower
        if extent.shape != (3,) or not np.all(np.isfinite(extent)) or np.any(extent <= 0):
            raise ValueError(f"occupancy grid needs a box with positive extent, got {lower} to {upper}")
        if resolution < 1:
            raise ValueError(f"occupancy grid resolution must be >= 1, got {resolution}")
        self.voxel_size = float(extent.max()) / resolution
        shape = np.maximum(np.ceil(extent / self.voxel_size - 1e-9), 1).astype(np.int64)
        self.state = np.zeros(tuple(int(n) for n in shape), dtype=np.uint8)
        self.upper = self.lower + shape * self.voxel_size
        if not 0 <= steep_deg < 90 or 0 < steep_deg <= np.degrees(np.arcsin(LEVEL_SIN)):
            raise ValueError(f"occupancy grid's steep band starts past the level band's 10 degrees and under "
                             f"90 (0: none), got {steep_deg}")
        if sectors not in SECTORS:
            raise ValueError(f"occupancy grid's sight bins split the horizon in 4 or 8, got {sectors}")
        self.votes, self.steep_deg, self.sectors = votes, steep_deg, sectors
        self.sides = np.zeros(self.state.size, np.uint32)  # bit b: measured from `sight_bin` b
        self.hits, self.passes = (np.zeros(self.state.size if votes else 0, np.uint32) for _ in range(2))

    @property
    def sight_bins(self) -> int:
        """How many directions `sight_bin` tells apart here: 12, or 16 with a steep band (twice that with 8
        sectors)."""
        return self.sectors * (4 if self.steep_deg else 3)

    def side_bins(self) -> np.ndarray:
        """The sight bins but the steep band's (each sector's first of four, `sight_bin`); all, without."""
        every = np.arange(self.sight_bins)
        return every[every % 4 != 0] if self.steep_deg else every

    def integrate(self, depth: np.ndarray, K: np.ndarray, c2w: np.ndarray,  # noqa: N803
                  stride: int = 1) -> None:
        """Fold in one z-depth image (H x W metres, 0 for no hit, NaN for not measured) taken at the OpenCV
        camera-to-world `c2w`.

        Free space is carved along every `stride`-th measured pixel's ray; every pixel's hit is marked
        occupied (with `votes`: the image's hit and pass votes, then each voxel it touched takes the
        majority).
        """
        depth = np.asarray(depth, dtype=np.float64)
        origin, rays = self._rays(K, c2w, depth.shape[1], depth.shape[0])
        lengths = np.linalg.norm(rays, axis=-1)
        ranges = np.where(depth > 0, depth * lengths, np.inf)  # z-depth to distance along the unit ray
        step = slice(None, None, stride)
        measured = np.isfinite(depth[step, step]).reshape(-1)
        sub_rays = rays[step, step].reshape(-1, 3)[measured]
        sub_ranges = ranges[step, step].reshape(-1)[measured]
        lengths = lengths[step, step].reshape(-1, 1)[measured]
        flat = self.state.reshape(-1)
        crossed = np.zeros(flat.size, dtype=bool)
        for index, valid in self._walk(origin, sub_rays / lengths, sub_ranges):
            crossed[index[valid]] = True
        hits = origin + rays[depth > 0] * depth[depth > 0, None]
        inside = self.contains(hits)
        voxels, toward = self.voxel_index(hits[inside]), rays[depth > 0][inside]
        hit = np.zeros(flat.size, dtype=bool)
        hit[voxels] = True
        toward /= np.linalg.norm(toward, axis=-1, keepdims=True)
        bins = sight_bin(toward, self.steep_deg, self.sectors)
        np.bitwise_or.at(self.sides, voxels, (1 << bins).astype(np.uint32))
        if not self.votes:
            flat[crossed & (flat != OCCUPIED)] = FREE
            flat[hit] = OCCUPIED
            return
        self.passes[crossed & ~hit] += 1
        self.hits[hit] += 1
        touched = crossed | hit
        flat[touched] = np.where(self.hits[touched] >= self.passes[touched], OCCUPIED, FREE)

    def gain(self, K: np.ndarray, c2w: np.ndarray, width: int, height: int,  # noqa: N803
             stride: int = 1, first: int = 0) -> int:
        """Distinct unknown voxels that every `stride`-th pixel's ray reaches before an occupied voxel (with
        `first` > 0, only each ray's first that many)."""
        return int(self.reached(K, c2w, width, height, stride, first).sum())

    def reached(self, K: np.ndarray, c2w: np.ndarray, width: int, height: int,  # noqa: N803
                stride: int = 1, first: int = 0) -> np.ndarray:
        """Which voxels (flat bool, the grid's size) are unknown and reached by every `stride`-th pixel's ray
        before an occupied voxel, with `first` > 0 only among the first that many unknown voxels of each
        ray: the voxels `gain` counts."""
        return self.look(K, c2w, width, height, stride, first)[0]

    def sighted(self, K: np.ndarray, c2w: np.ndarray, width: int, height: int,  # noqa: N803
                stride: int = 1) -> np.ndarray:
        """(voxels, `sight_bins`) bool: the occupied voxel every `stride`-th pixel's ray meets first (past
        free and unknown voxels), in the bin of the ray's direction (`sight_bin`)."""
        return self.look(K, c2w, width, height, stride, sides=True)[1]

    def look(self, K: np.ndarray, c2w: np.ndarray, width: int, height: int,  # noqa: N803
             stride: int = 1, first: int = 0, sides: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
        """`reached` and, with `sides`, `sighted` (else None) from one walk of the rays."""
        if first < 0:
            raise ValueError(f"a ray's first unknown voxels to count must be >= 0 (0: all), got {first}")
        origin, rays = self._rays(K, c2w, width, height, stride)
        rays = rays.reshape(-1, 3)
        rays = rays / np.linalg.norm(rays, axis=-1, keepdims=True)
        flat = self.state.reshape(-1)
        reached = np.zeros(flat.size, dtype=bool)
        sighted = np.zeros((flat.size, self.sight_bins), dtype=bool) if sides else None
        bins, done = sight_bin(rays, self.steep_deg, self.sectors) if sides else None, 0
        for index, valid in self._walk(origin, rays, np.full(len(rays), np.inf)):
            state = flat[index]
            occupied = valid & (state == OCCUPIED)
            blocked = np.logical_or.accumulate(occupied, axis=1)
            unknown = valid & ~blocked & (state == UNKNOWN)
            if first:  # a sample starts a voxel where its index differs from the sample before it
                entered = unknown & np.diff(index, axis=1, prepend=-1).astype(bool)
                unknown &= np.cumsum(entered, axis=1) <= first
            reached[index[unknown]] = True
            if sides and index.shape[1]:  # a chunk whose rays all miss the box has no samples
                met = occupied.any(axis=1)
                meets = index[np.arange(len(index)), occupied.argmax(axis=1)]
                sighted[meets[met], bins[done:done + len(index)][met]] = True
            done += len(index)
        return reached, sighted

    def frontier(self) -> np.ndarray:
        """Which voxels (flat bool) are unknown with a free face neighbour: the frontier between the space
        known to be empty and the unknown (Yamauchi, "A frontier-based approach for autonomous exploration",
        1997), where a surface not yet measured can lie."""
        free = np.pad(self.state == FREE, 1)  # a border of non-free voxels: every neighbour is a slice
        inner = slice(1, -1)
        beside = np.zeros(self.state.shape, dtype=bool)
        for axis in range(3):
            for near in (slice(None, -2), slice(2, None)):
                beside |= free[tuple(near if a == axis else inner for a in range(3))]
        return ((self.state == UNKNOWN) & beside).reshape(-1)

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(N,) True where a point lies inside the grid's box."""
        return np.all((points >= self.lower) & (points < self.upper), axis=-1)

    def voxel_index(self, points: np.ndarray) -> np.ndarray:
        """Flat index of the voxel holding each point (..., 3), clamped into the grid."""
        ijk = np.floor((points - self.lower) / self.voxel_size).astype(np.int64)
        ijk = np.clip(ijk, 0, np.array(self.state.shape) - 1)
        return np.ravel_multi_index(np.moveaxis(ijk, -1, 0), self.state.shape)

    def _rays(self, K: np.ndarray, c2w: np.ndarray, width: int,  # noqa: N803
              height: int, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """The camera centre and the world directions of every `stride`-th pixel's ray ((H, W, 3) at stride
        1), unit z in the camera."""
        pose = validate_pose(c2w)
        return pose[:3, 3], pixel_rays(K, width, height)[::stride, ::stride] @ pose[:3, :3].T

    def _walk(self, origin: np.ndarray, directions: np.ndarray,
              ends: np.ndarray) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Per chunk of unit-direction rays: (rays, samples) voxel indices of samples every half voxel
        inside the box, and whether each sample is before the ray's exit and before its end distance."""
        with np.errstate(divide="ignore", invalid="ignore"):
            near = (self.lower - origin) / directions
            far = (self.upper - origin) / directions
        enter = np.nanmax(np.minimum(near, far), axis=1).clip(min=0.0)
        leave = np.minimum(np.nanmin(np.maximum(near, far), axis=1), ends)
        missed = ~(enter < leave)  # rays that miss the box, or end before it
        enter[missed], leave[missed] = 0.0, 0.0
        step = self.voxel_size / 2.0
        start = ((origin - self.lower) / self.voxel_size).astype(np.float32)  # in voxel units from here on
        units = (directions / self.voxel_size).astype(np.float32)
        shape = np.array(self.state.shape)
        strides = np.array([shape[1] * shape[2], shape[2], 1])
        chunk = max(1, CHUNK_SAMPLES // int(np.ceil(np.linalg.norm(self.upper - self.lower) / step)))
        for first in range(0, len(directions), chunk):
            part = slice(first, first + chunk)
            samples = int(np.ceil((leave[part] - enter[part]).max(initial=0.0) / step))
            t = (enter[part, None] + (np.arange(samples) + 0.5) * step).astype(np.float32)
            valid = t < leave[part, None]
            index = np.zeros(t.shape, dtype=np.int32)
            for axis in range(3):
                cell = np.floor(start[axis] + t * units[part, axis, None]).astype(np.int32)
                index += np.clip(cell, 0, shape[axis] - 1, out=cell) * np.int32(strides[axis])
            yield index, valid
