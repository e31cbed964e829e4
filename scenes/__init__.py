"""Reconstruction targets: built-in textured buildings and user meshes, normalised.

Names are re-exported lazily (`common.lazy`): `import scenes.spec` stays light.
"""

from common.lazy import lazy_exports

_EXPORTS = {
    "DEFAULT_SCENE": "scenes.catalog", "list_scenes": "scenes.catalog", "load_scene": "scenes.catalog",
    "Lighting": "scenes.model", "Material": "scenes.model", "Part": "scenes.model", "Scene": "scenes.model",
    "MeshOrientation": "scenes.spec", "SceneSet": "scenes.spec", "SceneSpec": "scenes.spec",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
