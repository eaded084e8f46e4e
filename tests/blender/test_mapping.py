#!/usr/bin/python3
"""ctest blender.mapping: the add-on's closed-form mappings (mapping.py has no bpy; plain Python)."""
import math, os, sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "plugins", "blender", "whitted_blender"))
import mapping as m

def close(a, b, tol=1e-12):
    assert abs(a - b) <= tol * max(1.0, abs(b)), (a, b)

# 36 mm sensor, 50 mm lens, landscape: horizontal fov 2 atan(18/50), for AUTO and HORIZONTAL
expect = math.degrees(2 * math.atan(18 / 50))
close(m.horizontal_fov(50, 36, 24, 'AUTO', 640, 480), expect)
close(m.horizontal_fov(50, 36, 24, 'HORIZONTAL', 640, 480), expect)
close(expect, 39.59775270904693, 1e-9)  # the familiar 39.6 degrees
# AUTO, portrait: the sensor width spans the (larger) height, so horizontal = 2 atan(18/50 * w/h)
close(m.horizontal_fov(50, 36, 24, 'AUTO', 480, 640), math.degrees(2 * math.atan(18 / 50 * 480 / 640)))
# HORIZONTAL, portrait: still the width
close(m.horizontal_fov(50, 36, 24, 'HORIZONTAL', 480, 640), expect)
# VERTICAL: the 24 mm sensor height spans the image height -> horizontal 2 atan(12/50 * 4/3)
close(m.horizontal_fov(50, 36, 24, 'VERTICAL', 640, 480), math.degrees(2 * math.atan(12 / 50 * 640 / 480)))
close(m.horizontal_fov(50, 36, 24, 'VERTICAL', 640, 480), math.degrees(2 * math.atan(16 / 50)))

# Principled BSDF defaults (base 0.8, specular 0.5, roughness 0.5, metallic 0)
d = m.principled_to_lecture((0.8, 0.8, 0.8, 1.0), 0.5, 0.5, 0.0)
for k in range(3):
    close(d['kd'][k], 0.8); close(d['ka'][k], 0.08); close(d['km'][k], 0.0)
close(d['ks'], 0.5)
close(d['p'], 30.0)  # 2 / 0.5^4 - 2
# clamps: roughness 0 -> p 10000, roughness 1 -> 2/1 - 2 = 0 -> 1
close(m.principled_to_lecture((1, 1, 1), 0.5, 0.0, 0.0)['p'], 10000.0)
close(m.principled_to_lecture((1, 1, 1), 0.5, 1.0, 0.0)['p'], 1.0)
# metal: no diffuse, mirrors in its own colour
g = m.principled_to_lecture((1.0, 0.8, 0.2), 0.5, 0.2, 1.0)
assert g['kd'] == [0.0, 0.0, 0.0], g
assert g['km'] == [1.0, 0.8, 0.2], g

# Lights (docs/blender.md, Mapping): Cycles' point light of P W gives irradiance P/(4 pi d^2) and a
# Lambertian surface radiance rho E cos / pi; the lecture's kd I cos matches it at d_ref when
# I = P/(4 pi^2 d_ref^2). A sun of S W/m^2 is irradiance S: I = S/pi.
for power, colour, d in ((1000.0, (1, 1, 1), 7.0), (40.0, (1.0, 0.5, 0.25), 0.5)):
    got = m.point_intensity(power, colour, d)
    for k in range(3):
        close(got[k], power * colour[k] / (4 * math.pi ** 2 * d ** 2))
    # halving the distance quadruples the intensity (inverse square at the reference distance)
    close(m.point_intensity(power, colour, d / 2)[0], 4 * got[0])
for strength, colour in ((1.0, (1, 1, 1)), (3.0, (0.2, 0.4, 1.0))):
    got = m.sun_intensity(strength, colour)
    for k in range(3):
        close(got[k], strength * colour[k] / math.pi)
# d_ref: from the light to the bounding box's centre ...
box = ((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0))
light = (4.076245307922363, 1.0054539442062378, 5.903861999511719)  # Blender's default light
close(m.reference_distance(light, box), math.sqrt(sum(c * c for c in light)))
close(m.reference_distance((0.0, 0.0, 5.0), ((2.0, 2.0, 2.0), (4.0, 4.0, 4.0))), math.sqrt(9 + 9 + 4))
# ... at least r/sqrt(3), r the half diagonal: a lamp at the centre of a 10 m room gets the
# distance to the walls (5 m), one just off the centre too
room = ((-5.0, -5.0, -5.0), (5.0, 5.0, 5.0))
close(m.reference_distance((0.0, 0.0, 0.0), room), 5.0)
close(m.reference_distance((1.0, 0.0, 0.0), room), 5.0)
close(m.reference_distance((6.0, 0.0, 0.0), room), 6.0)
# nothing to light, or a point-sized box at the light: 1 m, never a division by zero
close(m.reference_distance((1.0, 2.0, 3.0), None), 1.0)
close(m.reference_distance((1.0, 2.0, 3.0), ((1.0, 2.0, 3.0), (1.0, 2.0, 3.0))), 1.0)
# Blender's default scene: 1000 W at 7.24 m -> I ~ 0.48 (the cube's kd 0.8: diffuse <= 0.39, not clipped)
i_default = m.point_intensity(1000.0, (1, 1, 1), m.reference_distance(light, box))[0]
assert 0.4 < i_default < 0.6, i_default

# dumps: exact round trip, and no NaN written
import json
x = {'a': 0.1 + 0.2}
assert json.loads(m.dumps(x))['a'] == x['a']
try:
    m.dumps({'a': float('nan')}); raise AssertionError("NaN was written")
except ValueError:
    pass
print("blender.mapping: all checks passed")
