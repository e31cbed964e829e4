"""Photoreal RGB-D rendering of a `scenes.Scene` with Mitsuba 3 (the paper's UAV Camera).

The scene is loaded once; each pose gets two cheap sensors and two passes
(docs/rendering.md): RGB with the configured integrator, spp and a Gaussian
filter; depth with 1 spp, a non-jittered stratified sampler (one ray through
each pixel centre) and a box filter, so edges never mix foreground and
background. Depth comes from the `aov` integrator's hit *position*, projected
on the optical axis: z-depth exactly, with no near-plane offset to undo.

Mitsuba's `look_at` camera frame is +Z forward, +Y up, +X towards image left;
an OpenCV camera-to-world maps to it as `c2w @ diag(-1, -1, 1, 1)`.

The RGB pass follows `RenderSettings`: pixel filter, integrator, spp, lighting
(`render.lighting`), texture detail (`render.texture_scale`) and resolution
(`RenderSettings.render_camera`: the lens is kept, so the field of view is).
Its linear output goes through `render.postprocess` (denoise, exposure, noise,
sRGB, JPEG); with the denoiser on, a third pass renders its albedo and normal
guides at the RGB pass's spp, filter and seed. With motion blur, both are the
mean over sub-frame poses (`render.motion_blur`); depth stays at the view's pose.
"""

from __future__ import annotations

import math

import numpy as np

from render.camera import UAVCamera
from render.lighting import scene_emitters
from render.motion_blur import subframe_poses
from render.postprocess import postprocess
from render.settings import LightingSettings, RenderSettings
from render.texture_scale import texture_dict
from render.variant import select_variant
from render.viewpoint import validate_pose
from scenes.model import Material, Part, Scene

OPENCV_TO_MITSUBA = np.diag([-1.0, -1.0, 1.0, 1.0])


class MitsubaRenderer:
    """Renders RGB (sRGB uint8) and z-depth (float32 metres) of one scene at any pose.

    Images have the size of `self.camera`: the given camera at the settings' `resolution_scale`.

    Example:
        >>> from scenes import load_scene
        >>> from render.viewpoint import Viewpoint, viewpoint_to_c2w
        >>> r = MitsubaRenderer(load_scene("test_building"), UAVCamera(64, 48))
        >>> rgb, depth = r.render(viewpoint_to_c2w(Viewpoint(2.0, 0.3, 0.4), r.center))
    """

    def __init__(self, scene: Scene, camera: UAVCamera, settings: RenderSettings | None = None) -> None:
        self.settings = settings or RenderSettings()
        self.mi = select_variant(self.settings.variant)
        self.variant: str = self.mi.variant()
        self.camera = self.settings.render_camera(camera)
        self.center = scene.center() if scene.parts else np.zeros(3)
        self._scene = self._load_scene(scene)
        self._rgb_integrator = self.mi.load_dict(
            {"type": self.settings.integrator, "max_depth": self.settings.max_depth}
            if self.settings.integrator == "path" else {"type": "direct"})
        self._depth_integrator = self.mi.load_dict({"type": "aov", "aovs": "dd.y:depth,p:position"})
        self._guide_integrator = (self.mi.load_dict({"type": "aov", "aovs": "albedo:albedo,nn:sh_normal"})
                                  if self.settings.denoiser != "off" else None)  # the denoiser's guides
        self._views_rendered = 0

    def render(self, c2w: np.ndarray, seed: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """RGB (H x W x 3 uint8 sRGB) and z-depth (H x W float32 m, 0 for no hit) at pose `c2w`.

        Args:
            c2w: 4x4 camera-to-world, OpenCV convention.
            seed: sampler seed of the RGB pass; default: the next per-view seed.
        """
        pose = validate_pose(c2w)
        return self._rgb(pose, seed), self._depth(pose)

    def render_rgb(self, c2w: np.ndarray, seed: int | None = None) -> np.ndarray:
        """The RGB pass only: H x W x 3 uint8 sRGB."""
        return self._rgb(validate_pose(c2w), seed)

    def render_depth(self, c2w: np.ndarray) -> np.ndarray:
        """The depth pass only: H x W float32 z-depth in metres, 0 where nothing is hit in range."""
        return self._depth(validate_pose(c2w))

    def _rgb(self, pose: np.ndarray, seed: int | None) -> np.ndarray:
        if seed is None:
            seed = self.settings.view_seed(self._views_rendered)
        self._views_rendered += 1
        poses = subframe_poses(pose, self.settings.motion_blur_m, self.settings.motion_blur_frames)
        image = self._mean_pass(poses, int(seed), self._rgb_integrator)
        albedo = normal = None
        if self.settings.denoiser != "off":
            guides = self._mean_pass(poses, int(seed), self._guide_integrator)
            albedo, normal = guides[..., 0:3], guides[..., 3:6]
        return postprocess(image[..., :3], self.settings, int(seed), albedo, normal)

    def _mean_pass(self, poses: list[np.ndarray], seed: int, integrator) -> np.ndarray:
        """One RGB-sensor pass of `integrator`: at one pose as rendered, over motion-blur sub-frames their
        mean, sub-frame k seeded `seed * frames + k` with `spp // frames` samples (at least 1)."""
        if len(poses) == 1:
            spp, seeds = self.settings.spp, [seed]
        else:
            spp = max(1, self.settings.spp // len(poses))
            seeds = [(seed * len(poses) + k) % 2**32 for k in range(len(poses))]
        images = [np.asarray(self.mi.render(self._scene, integrator=integrator, spp=spp, seed=s,
                                            sensor=self._sensor(p, self.settings.rgb_filter,
                                                                {"type": "independent"}, spp)))
                  for p, s in zip(poses, seeds)]
        return images[0] if len(images) == 1 else np.mean(images, axis=0, dtype=np.float32)

    def _depth(self, pose: np.ndarray) -> np.ndarray:
        sampler = {"type": "stratified", "jitter": False}
        sensor = self._sensor(pose, "box", sampler, 1)
        aov = np.asarray(self.mi.render(self._scene, sensor=sensor,
                                        integrator=self._depth_integrator, spp=1, seed=0))
        hit = aov[..., 0] > 0
        z = (aov[..., 1:4].astype(np.float64) - pose[:3, 3]) @ pose[:3, 2]
        valid = hit & (z >= self.camera.near_m) & (z <= self.camera.far_m)
        return np.where(valid, z, 0.0).astype(np.float32)

    def _sensor(self, c2w: np.ndarray, rfilter: str, sampler: dict, spp: int):
        mi = self.mi
        return mi.load_dict({
            "type": "perspective",
            "fov": self.camera.fov_x_deg,
            "fov_axis": "x",
            "near_clip": self.camera.near_m,
            "far_clip": self.camera.far_m,
            "to_world": mi.ScalarTransform4f(c2w @ OPENCV_TO_MITSUBA),
            "film": {"type": "hdrfilm", "width": self.camera.width, "height": self.camera.height,
                     "rfilter": {"type": rfilter}, "pixel_format": "rgba"},
            "sampler": {**sampler, "sample_count": spp},
        })

    def _load_scene(self, scene: Scene):
        mi = self.mi
        if scene.mitsuba_xml is not None:
            if self.settings.lighting != LightingSettings() or self.settings.texture_scale != 1.0:
                raise ValueError(f"{scene.mitsuba_xml} is a Mitsuba XML scene, rendered as is: lighting "
                                 "settings and texture_scale do not apply to it")
            return mi.load_file(str(scene.mitsuba_xml))
        bsdfs = {m.name: self._bsdf(m) for m in {p.material.name: p.material for p in scene.parts}.values()}
        items = {"type": "scene", **scene_emitters(scene.lighting, self.settings.lighting)}
        for i, part in enumerate(scene.parts):
            items[f"part_{i:04d}"] = self._mesh(part, bsdfs[part.material.name])
        return mi.load_dict(items)

    def _bsdf(self, material: Material):
        reflectance = (texture_dict(self.mi, material.texture, self.settings.texture_scale)
                       if material.texture is not None
                       else {"type": "rgb", "value": _srgb_to_linear(material.color)})
        if material.roughness is None:
            inner = {"type": "diffuse", "reflectance": reflectance}
        else:
            inner = {"type": "roughplastic", "diffuse_reflectance": reflectance,
                     "alpha": float(material.roughness)}
        # `diffuse` is one-sided: walls seen from inside (thin parts, open meshes) stay lit.
        return self.mi.load_dict({"type": "twosided", "bsdf": inner})

    def _mesh(self, part: Part, bsdf):
        mi = self.mi
        props = mi.Properties()
        props["bsdf"] = bsdf
        mesh = mi.Mesh(part.name, len(part.vertices), len(part.faces), props,
                       has_vertex_normals=False, has_vertex_texcoords=part.uv is not None)
        params = mi.traverse(mesh)
        # Buffer types differ per variant (dynamic arrays in scalar, JIT arrays in LLVM/CUDA).
        for key, array in (("vertex_positions", part.vertices.astype(np.float32)),
                           ("faces", part.faces.astype(np.uint32)),
                           ("vertex_texcoords", None if part.uv is None else part.uv.astype(np.float32))):
            if array is not None:
                params[key] = type(params[key])(array.ravel())
        params.update()
        return mesh


def _srgb_to_linear(color: tuple[float, float, float]) -> list[float]:
    return [c / 12.92 if c <= 0.04045 else math.pow((c + 0.055) / 1.055, 2.4) for c in color]
