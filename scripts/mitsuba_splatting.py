#!/usr/bin/env python3
"""How much of Mitsuba 3's lower error per sample is its pixel filter's
splatting (issue 44).

quadray samples its Gaussian pixel filter (σ 0.5 px) by jittering each
camera ray, and adds the sample to its own pixel only. Mitsuba 3 places its
samples uniformly in the pixel and splats each onto every pixel within the
filter's reach (2 px for this Gaussian), weighted by the filter, dividing
each pixel by its sum of weights. Both converge to the same filtered image,
but a splatted pixel averages the samples of its neighbours too.

For each scene (exported by `quadray export`), at SPP samples per pixel:
Mitsuba with the Gaussian (splatting) and with a one-pixel box filter (each
sample to its own pixel, no splatting), each against its own REF_SPP
reference, and quadray (`--filter none --brute-force`, the plain path
tracer) against the Gaussian reference. relMSE on linear radiance by
`quadray compare`. Prints a table; writes OUT/splatting.json.

Usage: python3 scripts/mitsuba_splatting.py [--scenes a.toml ...] [--spp 256]
"""

import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
from mitsuba_scene import arguments, mitsuba_dict, render  # noqa: E402
from quadray_cli import command_line, compare  # noqa: E402

import mitsuba as mi  # noqa: E402


def main():
    ap = arguments(__doc__, "results/mitsuba/splatting", 128, 96, 4096)
    ap.add_argument("--scenes", nargs="+", default=["scenes/glints.toml", "scenes/curved_mirrors.toml",
                                                          "scenes/tests/lens_fog.toml"])
    ap.add_argument("--spp", type=int, default=256)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    w, h = args.width, args.height
    filters = {"gaussian": {"type": "gaussian", "stddev": 0.5}, "box": {"type": "box"}}
    rows = []
    for scene in args.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        out = os.path.join(args.out, name)
        export = os.path.join(out, "export")
        subprocess.run([args.quadray, "export", scene, "-o", export, "--cells", "512"], check=True,
                       capture_output=True)
        o = lambda f: os.path.join(out, f)  # noqa: E731
        row = {"scene": scene, "spp": args.spp, "reference_spp": args.ref_spp, "size": [w, h]}
        for label, rfilter in filters.items():
            for spp, seed, image in [(args.ref_spp, 1000, "reference"), (args.spp, 1, "mitsuba")]:
                scene_dict = mitsuba_dict(export, w, h, spp, seed)
                scene_dict["sensor"]["film"]["rfilter"] = rfilter
                render(mi.load_dict(scene_dict), o(f"{image}-{label}.exr"), spp, seed)
            row[f"mitsuba_{label}_relmse"] = compare(args.quadray, o(f"reference-{label}.exr"),
                                                     o(f"mitsuba-{label}.exr"))[0]
        subprocess.run([args.quadray, "render", scene, "--width", str(w), "--height", str(h), "--spp",
                        str(args.spp), "--seed", "1", "--no-denoise", "--filter", "none", "--brute-force", "-o",
                        o("quadray.exr")], check=True, capture_output=True)
        row["quadray_relmse"] = compare(args.quadray, o("reference-gaussian.exr"), o("quadray.exr"))[0]
        rows.append(row)
        print(f"{name}: {args.spp} spp relMSE: Mitsuba splatting (Gaussian) {row['mitsuba_gaussian_relmse']:.5f}, "
              f"Mitsuba one pixel per sample (box) {row['mitsuba_box_relmse']:.5f}, "
              f"quadray plain (jittered Gaussian) {row['quadray_relmse']:.5f}", flush=True)
    command = command_line("scripts/mitsuba_splatting.py", args)
    with open(os.path.join(args.out, "splatting.json"), "w") as f:
        json.dump({"command": command, "mitsuba": mi.__version__ + " llvm_ad_rgb", "scenes": rows}, f, indent=2)


if __name__ == "__main__":
    main()
