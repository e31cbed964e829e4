"""Reconstruction targets: built-in textured buildings and user meshes, normalised."""

from scenes.catalog import DEFAULT_SCENE, list_scenes, load_scene
from scenes.model import Lighting, Material, Part, Scene

__all__ = ["DEFAULT_SCENE", "Lighting", "Material", "Part", "Scene", "list_scenes", "load_scene"]
