"""Bring-your-own targets: mesh files through trimesh, Mitsuba XML scenes as they are (trusted like code).

OBJ (with MTL and textures), PLY, GLB / glTF, DAE (pycollada), STL and OFF are
read with trimesh, one `Part` per textured sub-mesh, keeping each material's
base colour and texture. A sub-mesh without a texture gets a procedural one
projected by planar UVs. The result is normalised (docs/conventions.md) after
turning `up_axis` to z, over the vertices faces use (unreferenced ones are
dropped), and stands on a textured ground. Arrays are checked before use: NaN
vertices, meshes without faces, out-of-range face indices, corrupt textures, a
target of zero or overflowing size or of no area raise a ValueError naming the
file and the fault; so do referenced files that are not regular files (a FIFO
would block) and short ASCII PLY bodies (`scenes.mesh_files`). A referenced file
that is missing is a warning. A Mitsuba XML file is loaded once on load, so its
errors name it too.
"""

from __future__ import annotations

import hashlib
import io
import warnings
from pathlib import Path

import numpy as np
import trimesh
from PIL import Image

from common.cache import cache_file
from common.io import cache_dir
from scenes.mesh_files import GuardedResolver, check_ply_counts, resolve_obj_indices, texture_failures
from scenes.model import Material, Part, Scene, validate_arrays
from scenes.normalise import make_ground, normalise_parts
from scenes.surface import Finish, make_part, planar_uv

MESH_SUFFIXES = (".obj", ".ply", ".glb", ".gltf", ".dae", ".stl", ".off")
"""File types read as meshes."""
XML_SUFFIX = ".xml"
"""A Mitsuba scene file, rendered as is."""
UNTEXTURED = Finish("stone_sandstone")
"""The procedural finish of sub-meshes that carry no texture."""
UNTEXTURED_TILE_M = 0.35
"""Metres (normalised) per tile of the procedural texture."""
MIN_TARGET_AREA = 1e-9
"""Least total face area of a normalised target (1 m across), square metres: below it every face is
degenerate (repeated or collinear vertices) and nothing would be seen."""


def is_scene_file(spec: str) -> bool:
    """Whether `spec` names a mesh or Mitsuba XML file (by its suffix)."""
    return Path(spec).suffix.lower() in MESH_SUFFIXES + (XML_SUFFIX,)


def load_file_scene(path: str | Path, up_axis: str = "z", ground: bool = True) -> Scene:
    """The scene of a mesh file (normalised, on a ground) or of a Mitsuba XML file (as is).

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: unknown type, unreadable file, or invalid mesh data.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"scene file not found: {path}")
    suffix = path.suffix.lower()
    if suffix == XML_SUFFIX:
        _check_mitsuba_xml(path)
        return Scene(name=str(path), parts=(), mitsuba_xml=path.resolve())
    if suffix not in MESH_SUFFIXES:
        raise ValueError(
            f"{path}: unsupported file type {suffix!r}; use one of {', '.join(MESH_SUFFIXES + (XML_SUFFIX,))}"
        )
    raw = _read_parts(path)
    try:
        parts = list(normalise_parts(raw, up_axis))
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from err
    area = sum(_area(p) for p in parts if p.target)
    if not area >= MIN_TARGET_AREA:
        raise ValueError(f"{path}: the target mesh has no area ({area:.3g} m^2 once normalised): every face "
                         f"repeats or lines up its vertices, so nothing would be seen")
    parts = [_with_procedural_texture(p) if p.uv is None else p for p in parts]
    if ground:
        parts.append(make_ground(Finish("grass"), 0, half_m=3.0, tile_m=0.5))
    return Scene(name=str(path), parts=tuple(parts))


def _area(part: Part) -> float:
    corners = part.vertices[part.faces]
    with np.errstate(over="ignore", invalid="ignore"):
        cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return 0.5 * float(np.linalg.norm(cross, axis=1).sum())


def _load_checked(path: Path) -> trimesh.Scene:
    """trimesh's scene of `path`, its referenced files opened by a `GuardedResolver`, its OBJ indices
    resolved and its PLY counts checked; ValueError naming the file for what trimesh would let pass."""
    resolver, suffix, text = GuardedResolver(path), path.suffix.lower(), None
    try:
        if suffix == ".ply":
            check_ply_counts(path)
        if suffix == ".obj":
            text = resolve_obj_indices(path.read_bytes().decode("utf-8", errors="replace"))
    except (ValueError, OSError) as err:
        raise ValueError(f"{path}: {err}") from err
    try:
        with texture_failures() as failures:
            if text is not None:
                loaded = trimesh.load(io.BytesIO(text.encode()), file_type="obj", resolver=resolver,
                                      force="scene", process=False)
            else:
                loaded = trimesh.load(str(path), force="scene", process=False, resolver=resolver)
    except Exception as err:  # trimesh raises many types for malformed files
        raise ValueError(f"{path}: cannot read mesh ({type(err).__name__}: {err})") from err
    if resolver.refused:
        raise ValueError(f"{path}: {resolver.refused[0]}")
    if failures:
        raise ValueError(f"{path}: a texture cannot be used ({failures[0]}); fix or remove it")
    for name in resolver.missing:
        warnings.warn(f"{path}: referenced file {name!r} not found; its parts get the procedural texture",
                      stacklevel=4)
    return loaded


def _read_parts(path: Path) -> list[Part]:
    loaded = _load_checked(path)
    parts: list[Part] = []
    for node in loaded.graph.nodes_geometry:
        transform, geometry_name = loaded.graph[node]
        geometry = loaded.geometry[geometry_name]
        if not isinstance(geometry, trimesh.Trimesh):
            continue
        name = f"{len(parts):03d}_{geometry_name}"
        try:
            parts.append(_part(geometry, transform, name))
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from err
    if not parts:
        raise ValueError(f"{path}: the file holds no triangle mesh with faces")
    return parts


def _part(geometry: trimesh.Trimesh, transform: np.ndarray, name: str) -> Part:
    """One checked `Part`, placed by its node transform, keeping only the vertices its faces use."""
    vertices = np.asarray(geometry.vertices, dtype=np.float64)
    faces = np.asarray(geometry.faces, dtype=np.int64).reshape(-1, 3)
    validate_arrays(name, vertices, faces, None)
    with np.errstate(over="ignore", invalid="ignore"):
        vertices = trimesh.transformations.transform_points(vertices, transform)
    material, uv = _material(geometry, name)
    used, faces = np.unique(faces, return_inverse=True)
    faces = faces.reshape(-1, 3)
    return Part(name, vertices[used], faces, material, None if uv is None else uv[used])


def _material(mesh: trimesh.Trimesh, name: str) -> tuple[Material, np.ndarray | None]:
    """The sub-mesh's material (base colour, texture saved to the cache) and Mitsuba-convention UVs."""
    visual = mesh.visual
    if isinstance(visual, trimesh.visual.TextureVisuals) and visual.material is not None:
        simple = visual.material
        if isinstance(simple, trimesh.visual.material.PBRMaterial):
            simple = simple.to_simple()
        color = tuple(float(c) / 255.0 for c in np.asarray(simple.diffuse)[:3])
        image = getattr(simple, "image", None)
        uv = None if visual.uv is None else np.asarray(visual.uv, dtype=np.float64)
        if image is not None and uv is not None and uv.shape == (len(mesh.vertices), 2):
            if not np.all(np.isfinite(uv)):
                raise ValueError(f"part {name!r}: texture coordinates contain NaN or infinite values")
            flipped = np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1)
            return Material(name, color, _save_texture(image, name), None), flipped
        return Material(name, color), None
    return Material(name), None


def _save_texture(image: Image.Image, name: str) -> Path:
    """Write a mesh's texture to the cache as an sRGB PNG named by its content hash (`common.cache`)."""
    buffer = io.BytesIO()
    try:
        image.convert("RGB").save(buffer, format="PNG")
    except Exception as err:  # PIL decodes lazily here and raises many types for corrupt data
        raise ValueError(f"part {name!r}: cannot decode its texture ({type(err).__name__}: {err})") from err
    data = buffer.getvalue()
    path = cache_dir() / "mesh_textures" / f"{hashlib.sha1(data).hexdigest()}.png"
    return cache_file(path, lambda tmp: tmp.write_bytes(data))


def _check_mitsuba_xml(path: Path) -> None:
    """Load a Mitsuba scene file once, so that its errors name the file (the XML is trusted like code)."""
    import mitsuba as mi

    try:
        if mi.variant() is None:
            mi.set_variant("scalar_rgb")
        mi.load_file(str(path))
    except Exception as err:  # Mitsuba raises RuntimeError, and others for odd files
        raise ValueError(f"{path}: cannot load Mitsuba scene ({type(err).__name__}: {err})") from err


def _with_procedural_texture(part: Part) -> Part:
    """An untextured part re-made with planar UVs and the procedural `UNTEXTURED` finish."""
    corners = part.vertices[part.faces]
    uv = planar_uv(corners, UNTEXTURED_TILE_M)
    material = UNTEXTURED.material(part.material.name, 0)
    return make_part(part.name, corners, uv, material, part.target, merge=False)
