#!/usr/bin/env python3
"""Checks the Mitsuba conversion's tangent frame for normal maps (issue 44).

A constant normal map tilted towards +u and +v (n ∝ (0.3, 0.5, 0.81)) on a
diffuse floor (planar (u, v) = (x, z): left-handed under Mitsuba's frame)
and a ball (spherical mapping: right-handed), lit from one side by a sphere
light, direct light only. quadray (`--filter none`, 1024 spp) against
Mitsuba with the map as mitsuba_scene.py converts it, with its y never
negated, and with the opposite choice on each mesh (negated on the ball,
not on the floor): the conversion must agree with
quadray (relMSE below 0.001) and both others must not (above 0.5). Random
bumps, as in glints.toml, are symmetric and cannot tell the sign.

Usage: python3 scripts/mitsuba_normal_map_check.py [--quadray target/release/quadray]
Exits with 1 when the check fails.
"""

import glob
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
import mitsuba_scene  # noqa: E402
from mitsuba_scene import arguments, mitsuba_dict, render  # noqa: E402
from quadray_cli import compare  # noqa: E402

import mitsuba as mi  # noqa: E402
import numpy as np  # noqa: E402

SCENE = """background = [0, 0, 0]

[image]
width = 96
height = 72
spp = 1024
max_depth = 1

[camera]
position = [0, 3, 3]
look_at = [0, 0, 0]
fov = 50

[[materials]]
name = "tilted"
albedo = [0.8, 0.8, 0.8]
normal_map = "tilt.png"

[[objects]]
name = "floor"
material = "tilted"
plane = {}
clip = { min = [-3, -0.01, -3], max = [3, 0.01, 3] }
uv = { mapping = "planar", u_axis = [1, 0, 0], v_axis = [0, 0, 1], scale = [1, 1] }

[[objects]]
name = "ball"
material = "tilted"
sphere = { radius = 0.6 }
translate = [0, 0.8, 0]
uv = { mapping = "spherical", scale = [1, 1] }

[[lights]]
type = "sphere"
position = [1.0, 2.5, -2.0]
radius = 0.2
radiance = [300, 300, 300]
"""


def main():
    args = arguments(__doc__, "", 96, 72, 1024).parse_args()
    with tempfile.TemporaryDirectory() as d:
        n = np.array([0.3, 0.5, 0.81])
        n /= np.linalg.norm(n)
        texel = np.round((n + 1) / 2 * 255).astype(np.uint8)
        mi.Bitmap(np.tile(texel, (8, 8, 1)), mi.Bitmap.PixelFormat.RGB).write(os.path.join(d, "tilt.png"))
        scene = os.path.join(d, "tilt.toml")
        with open(scene, "w") as f:
            f.write(SCENE)
        export = os.path.join(d, "export")
        subprocess.run([args.quadray, "export", scene, "-o", export, "--cells", "128"], check=True,
                       capture_output=True)
        subprocess.run([args.quadray, "render", scene, "--filter", "none", "--no-denoise", "--width",
                        str(args.width), "--height", str(args.height), "--spp", str(args.ref_spp), "-o",
                        os.path.join(d, "quadray.exr")], check=True, capture_output=True)
        converted = mitsuba_scene._left_handed_uv
        choices = {"as converted": converted, "y never negated": lambda ply: False,
                   "the opposite": lambda ply: not converted(ply)}
        errors = {}
        for label, left_handed in choices.items():
            mitsuba_scene._left_handed_uv = left_handed
            for f in glob.glob(os.path.join(export, "texture-*-flipped-y.exr")):
                os.remove(f)
            image = os.path.join(d, "mitsuba.exr")
            render(mi.load_dict(mitsuba_dict(export, args.width, args.height, args.ref_spp, 3)), image,
                   args.ref_spp, 3)
            errors[label] = compare(args.quadray, os.path.join(d, "quadray.exr"), image)
            print(f"Mitsuba, normal map {label}: relMSE {errors[label][0]:.5f} FLIP {errors[label][1]:.4f} "
                  "against quadray", flush=True)
        mitsuba_scene._left_handed_uv = converted
    ok = errors["as converted"][0] < 0.001 and all(e[0] > 0.5 for k, e in errors.items() if k != "as converted")
    print("the conversion's tangent frame matches quadray's" if ok else "FAILED: the tangent frames differ")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
