#!/usr/bin/python3
"""ctest blender.errors / blender.cancel / blender.check_pov / blender.exposure: run tests/blender/checks.py MODE in
headless Blender and assert on what it recorded. Usage: test_checks.py MODE"""
import json, math, os, shutil, sys, tempfile
mode = sys.argv[1]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from headless import blender, require_blender, skip  # noqa: E402  (tests/blender/headless.py)
require_blender()
if mode == "check_pov" and shutil.which("povray") is None:
    skip("povray is not installed (apt-get install povray)")
out = tempfile.mkdtemp(prefix=f"whitted-blender-{mode}-")
blender("checks.py", mode, out)
res = json.load(open(os.path.join(out, "result.json")))
if mode == "errors":
    assert "camera lens shift is not supported" in res["shift"], res["shift"]
    assert "Traceback" not in res["shift"], res["shift"]
    assert "no camera" in res["no_camera"], res["no_camera"]
    assert "no camera" in res["render_no_camera"], res["render_no_camera"]
    assert res["kept"] == "old", "a failed export clobbered the existing file"
    assert not res["part_left"], "a failed export left FILE.part"
    assert res["ortho_landscape"]["type"] == "orthographic"
    assert res["ortho_landscape"]["view_width"] == 5.0, res["ortho_landscape"]  # ortho_scale spans the width
    assert res["ortho_portrait"]["view_width"] == 5.0 * 48 / 64, res["ortho_portrait"]  # ...the height
    assert abs(res["persp"]["fov"] - math.degrees(2 * math.atan(18 / 50))) < 1e-12, res["persp"]
    assert res["background"] == [0.5, 1.0, 1.5], res["background"]  # Background node Color x Strength 2
    print(f"blender.errors: shift and no-camera refused, file kept; ortho {res['ortho_landscape']['view_width']}"
          f"/{res['ortho_portrait']['view_width']}, fov {res['persp']['fov']}")
elif mode == "cancel":
    full_estimate = 16 * res["full_sixteenth_seconds"]  # 800x600x1 is 1/16 of 1600x1200x4
    assert res["cancelled"], res
    assert res["calls"]["break"] == 2, res  # the render stopped at the first True
    assert res["cancel_seconds"] < 0.5 * full_estimate, res
    assert not res["cancelled_after_full"], res
    print(f"blender.cancel: cancelled 1600x1200x4 in {res['cancel_seconds']:.2f} s "
          f"(uncancelled estimate {full_estimate:.1f} s)")
elif mode == "check_pov":
    assert res["passed"] is True and res["verdict"].startswith("PASS"), res["verdict"]
    assert os.path.isfile(res["path"]), res
    assert os.path.isfile(os.path.join(res["report"], "report.html")), res
    assert os.path.isfile(os.path.join(res["report"], "metrics.json")), res
    note = res["note"]
    assert res["use_stamp_note"] and note.startswith("whitted check: PASS"), note
    assert "% of pixels within tolerance" in note and "PSNR" in note and res["report"] in note, note
    print(f"blender.check_pov: {res['verdict']}; stamp note: {note}")
elif mode == "exposure":
    # docs/blender.md, Mapping: a point light of P W -> I = P/(4 pi^2 d_ref^2), d_ref = the
    # distance to the geometry's bounding-box centre; a sun of S W/m^2 -> I = S/pi.
    def near(a, b, rel):
        return abs(a - b) <= rel * abs(b)
    for kind, expect in (("POINT", lambda e, h: e / (4 * math.pi ** 2 * h ** 2)),
                         ("SUN", lambda e, h: e / math.pi)):
        p = res["plane_" + kind]
        radiance = expect(p["energy"], p["height"])  # white Lambertian plane, head on
        assert near(p["cycles"], radiance, 0.02), (kind, "Cycles does not give the derivation's radiance", p, radiance)
        assert all(near(i, radiance, 1e-6) for i in p["intensity"]), (kind, p, radiance)
        assert near(p["whitted"], radiance, 0.01), (kind, p, radiance)
    light = res["light"]
    d_ref = math.dist(light["location"], (0, 0, 0))  # the default cube spans [-1, 1]^3
    i_expect = light["energy"] / (4 * math.pi ** 2 * d_ref ** 2)
    for case, factor in (("factory", 1.6), ("direct", 1.5)):
        c = res[case]
        assert c["pixels"] > 1000, c  # the cube covers part of the 192x108 frame
        assert all(near(i, i_expect, 1e-6) for i in c["lights"][0]["intensity"]), (c["lights"], i_expect)
        assert c["clipped"] < 0.01, f"{case}: {100 * c['clipped']:.1f}% of the cube's pixels clipped"
        ratio = c["cycles_mean"] / c["whitted_mean"]
        assert 1 / factor <= ratio <= factor, f"{case}: Cycles/Whitted {ratio:.3f} not within {factor}"
    print("blender.exposure: " + "; ".join(
        f"{k}: cube mean Cycles {res[k]['cycles_mean']:.4f} Whitted {res[k]['whitted_mean']:.4f} "
        f"(ratio {res[k]['cycles_mean'] / res[k]['whitted_mean']:.3f}), {100 * res[k]['clipped']:.2f}% clipped"
        for k in ("factory", "direct")) + "; white plane: " + "; ".join(
        f"{k} Cycles {res['plane_' + k]['cycles']:.4f} Whitted {res['plane_' + k]['whitted']:.4f}"
        for k in ("POINT", "SUN")) + f"; Cycles took {res['factory_cycles_seconds']:.1f} s")
else:
    sys.exit(f"unknown mode {mode}")
