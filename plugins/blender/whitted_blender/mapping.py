"""Blender -> Whitted scene description (a dict in docs/scene-format.md's terms).

Kept free of `bpy` at import time where it can be, so the closed-form mappings (camera fov,
Principled BSDF -> lecture material) can be tested without Blender.
"""
import json
import math


class MappingError(Exception):
    """A scene Whitted cannot render faithfully; the message is shown to the user as is."""


def horizontal_fov(lens_mm, sensor_width, sensor_height, sensor_fit, width, height):
    """Horizontal field of view in degrees (Whitted's `fov` is horizontal).

    Blender's sensor fit: AUTO fits the sensor width to the larger image side, HORIZONTAL to the
    width, VERTICAL fits sensor_height to the image height.
    """
    aspect = width / height
    if sensor_fit == 'VERTICAL':
        half_v = math.atan(sensor_height / 2 / lens_mm)
        return math.degrees(2 * math.atan(math.tan(half_v) * aspect))
    if sensor_fit == 'AUTO' and height > width:
        half_v = math.atan(sensor_width / 2 / lens_mm)
        return math.degrees(2 * math.atan(math.tan(half_v) * aspect))
    return math.degrees(2 * math.atan(sensor_width / 2 / lens_mm))


def principled_to_lecture(base, specular, roughness, metallic):
    """Default lecture material for a Principled BSDF that never set the Whitted panel.

    base colour -> kd (scaled by 1 - metallic), ka = 0.1 * base, ks = specular (scalar),
    p = 2 / roughness^4 - 2 (the Blinn-Phong exponent of the same Beckmann width), clamped to
    [1, 10000], km = metallic * base (a metal mirrors in its own colour).
    """
    r = max(roughness, 1e-3)
    p = min(max(2.0 / r ** 4 - 2.0, 1.0), 10000.0)
    base = [float(c) for c in base[:3]]
    return {
        'ka': [0.1 * c for c in base],
        'kd': [(1.0 - metallic) * c for c in base],
        'ks': float(specular),
        'p': p,
        'km': [metallic * c for c in base],
    }


def point_intensity(power_w, colour, d_ref):
    """Whitted intensity of a Blender point light of `power_w` watts, exposed for distance d_ref.

    Cycles/EEVEE: a point light of P watts emits P/(4 pi) W/sr, so a surface at distance d facing
    it receives irradiance E = P/(4 pi d^2), and a Lambertian surface of albedo rho sends radiance
    rho E cos / pi. The lecture's diffuse term is kd I cos (no falloff), so the same radiance at
    d_ref needs I = E(d_ref)/pi = P/(4 pi^2 d_ref^2) (docs/blender.md, Mapping).
    """
    scale = power_w / (4 * math.pi ** 2 * d_ref ** 2)
    return [scale * float(c) for c in colour[:3]]


def sun_intensity(strength, colour):
    """Whitted intensity of a Blender sun of `strength` W/m^2: the strength is the irradiance E on
    a surface facing it, a Lambertian surface sends rho E cos / pi, so I = E / pi."""
    scale = strength / math.pi
    return [scale * float(c) for c in colour[:3]]


def reference_distance(light_position, box):
    """The distance at which a point light's exposure is matched (docs/blender.md, Mapping).

    `box` is the world-space bounding box (min corner, max corner) of the geometry, or None.
    The distance from the light to the box's centre, but at least r/sqrt(3) (r: the half
    diagonal), the distance from the centre to the faces of the cube inscribed in the bounding
    sphere: a lamp inside the geometry (in a room) gets the exposure of the nearest wall, never
    an unbounded intensity. Without geometry (nothing to light), or a point-sized box at the
    light, 1 m.
    """
    if box is None:
        return 1.0
    lo, hi = box
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    floor = math.dist(lo, hi) / 2 / math.sqrt(3)
    d = max(math.dist(light_position, centre), floor)
    return d if d > 0 else 1.0


def dumps(description):
    """JSON text of a description; Python's float repr round-trips, so the text is exact."""
    return json.dumps(description, indent=1, allow_nan=False)
