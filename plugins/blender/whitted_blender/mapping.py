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


def dumps(description):
    """JSON text of a description; Python's float repr round-trips, so the text is exact."""
    return json.dumps(description, indent=1, allow_nan=False)
