"""The lights of a generated scene as Mitsuba emitter dicts: the scene's sun and sky, or Mitsuba's `sunsky`.

World frame z up (docs/conventions.md). The `uniform` model is a `directional`
sun of the scene's irradiance plus a `constant` sky: with default settings the
dicts are exactly those of earlier renders. The `sunsky` model is Mitsuba's
Hosek-Wilkie sun and sky; its emitter space is world space, its local z the
zenith, and `sun_direction` points towards the sun. Its radiance is physical
(W m^-2 sr^-1 nm^-1 through the CIE Y normalisation), so it is scaled by
`SUNSKY_SCALE` to the brightness of the scene's own lighting.
"""

from __future__ import annotations

from dataclasses import replace

from render.settings import LightingSettings
from scenes.model import Lighting

SUNSKY_SCALE = 3.44
"""Scale on sunsky's sun and sky radiance. Measured: a white Lambertian ground under the default lighting
(sun 3.0 at 50 degrees elevation, sky (0.55, 0.6, 0.7)) receives a luminance-weighted irradiance of 4.17;
under sunsky (turbidity 3, sun at 50 degrees) 1.21 (sun 0.96 + sky 0.25), path-traced at 1024 spp. The
ratio is the scale, so the two models match at the default sun; elsewhere sunsky varies physically."""


def scene_emitters(lighting: Lighting, settings: LightingSettings = LightingSettings()) -> dict[str, dict]:
    """Mitsuba emitter dicts (by scene key) for a scene's `lighting` under `settings`."""
    sun_on = settings.light_mode != "overcast"
    sky_on = settings.light_mode != "hard_sun"
    light = replace(lighting, **{name: value for name, value in
                                 (("sun_elevation_deg", settings.sun_elevation_deg),
                                  ("sun_azimuth_deg", settings.sun_azimuth_deg)) if value is not None})
    if settings.sky_model == "sunsky":
        return {"sky": {"type": "sunsky", "sun_direction": (-light.sun_direction()).tolist(),
                        "turbidity": float(settings.turbidity),
                        "sun_scale": SUNSKY_SCALE if sun_on else 0.0,
                        "sky_scale": SUNSKY_SCALE if sky_on else 0.0}}
    emitters = {}
    if sun_on:
        emitters["sun"] = {"type": "directional", "direction": light.sun_direction().tolist(),
                           "irradiance": {"type": "rgb", "value": [light.sun_irradiance] * 3}}
    if sky_on:
        emitters["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": list(light.sky_radiance)}}
    return emitters

