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

# dumps: exact round trip, and no NaN written
import json
x = {'a': 0.1 + 0.2}
assert json.loads(m.dumps(x))['a'] == x['a']
try:
    m.dumps({'a': float('nan')}); raise AssertionError("NaN was written")
except ValueError:
    pass
print("blender.mapping: all checks passed")
