#!/usr/bin/env python3
"""quadray beside Mitsuba 3 on scenes/spheres.toml (issue 28 item 5).

The scene is one both renderers express exactly: a checkered floor (a
clipped plane), a rough aluminium sphere (GGX, alpha = roughness^2 = 0.0625,
Rakic's index of aluminium in quadray, Mitsuba's "Al"), a glass sphere (index
1.5) and a one-sided 2 x 2 rect light; the same camera (vertical field of
view 40) and paths of 5 surface
interactions (quadray's max_depth = 5 is Mitsuba's max_depth = 6, which
counts the camera segment). Mitsuba runs its `path` integrator on the
`llvm_ad_rgb` variant with the `independent` sampler and a box pixel
filter: each of its samples counts in its own pixel only, as each of
quadray's does (quadray draws its Gaussian pixel filter, sigma 0.5 px, by
jittering the camera rays). Mitsuba's Gaussian filter would splat every
sample into the pixels around it and so average neighbouring pixels'
samples, which lowers its per-pixel error for a blurrier image: not an
equal-sample comparison.

Printed, measured in one run on this machine:
  * samples per second of each renderer at WIDTH x HEIGHT and SPP, after an
    untimed warm-up (Mitsuba's LLVM kernels and lavapipe's shaders compile at
    the first render): Mitsuba timed around mi.render, quadray by its own
    `render --bench` full-render figure (the same span: no start-up, no
    upload);
  * relMSE on linear radiance at 16 and 64 spp (ERR_WIDTH x ERR_HEIGHT,
    seeds 1..SEEDS averaged) of each renderer against its own reference of
    REF_SPP spp (another seed), all computed by `quadray compare`.

Usage: pip install mitsuba==3.9.1; apt-get install libllvm19; cargo build --release;
  python3 scripts/mitsuba_side_by_side.py [--quadray target/release/quadray] [--out results/mitsuba]
"""

import json
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
from mitsuba_scene import arguments, render  # noqa: E402
from quadray_cli import relmse  # noqa: E402

import mitsuba as mi  # noqa: E402
from mitsuba import ScalarTransform4f as T  # noqa: E402


def scene_dict(width, height, spp, seed):
    """scenes/spheres.toml as a Mitsuba scene."""
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 6},
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "y",
            "to_world": T().look_at(origin=[0, 1.6, 5.5], target=[0, 0.7, 0], up=[0, 1, 0]),
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
        # The 12 x 12 floor carrying the 32 x 32 checker once (Mitsuba's
        # checkerboard has 2 x 2 cells per uv unit).
        "floor": {
            "type": "rectangle",
            "to_world": T().rotate([1, 0, 0], -90).scale([6, 6, 1]),
            "bsdf": {
                "type": "diffuse",
                "reflectance": {
                    "type": "checkerboard",
                    "color0": {"type": "rgb", "value": [0.8, 0.8, 0.78]},
                    "color1": {"type": "rgb", "value": [0.1, 0.1, 0.12]},
                    "to_uv": mi.ScalarTransform4f().scale([16, 16, 1]),
                },
            },
        },
        "aluminium": {
            "type": "sphere",
            "center": [-0.9, 0.71, 0],
            "radius": 0.7,
            "bsdf": {"type": "roughconductor", "material": "Al", "distribution": "ggx", "alpha": 0.0625},
        },
        "glass": {
            "type": "sphere",
            "center": [0.9, 0.71, 0.3],
            "radius": 0.7,
            "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
        },
        # 2 x 2 at height 3.5, emitting downward (the rectangle's normal is +z
        # before the rotation).
        "light": {
            "type": "rectangle",
            "to_world": T().translate([0, 3.5, 0]).rotate([1, 0, 0], 90),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [6, 6, 5.6]}},
        },
    }


def mitsuba_render(path, width, height, spp, seed):
    """Renders to `path` (EXR) and returns the seconds mi.render took."""
    return render(mi.load_dict(scene_dict(width, height, spp, seed)), path, spp, seed)


def quadray_render(quadray, path, width, height, spp, seed, bench=False):
    """Renders to `path` (EXR, without the extension added); returns the
    full render's samples per second when `bench`."""
    cmd = [quadray, "render", "scenes/spheres.toml", "--width", str(width), "--height", str(height),
           "--spp", str(spp), "--seed", str(seed), "-o", path]
    if bench:
        cmd.append("--bench")
    done = subprocess.run(cmd, check=True, capture_output=True, text=True)
    out = done.stdout + done.stderr  # the benchmark table is written to stderr
    if bench:
        return float(re.search(r"^full render\s+[0-9.]+\s+([0-9]+)", out, re.M).group(1))
    return None


def main():
    ap = arguments(__doc__, "results/mitsuba", 1024, 768, 1024)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--err-width", type=int, default=512)
    ap.add_argument("--err-height", type=int, default=384)
    ap.add_argument("--seeds", type=int, default=4)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    o = lambda name: os.path.join(args.out, name)  # noqa: E731

    # Throughput: warm up, then time (Mitsuba twice, the faster kept).
    mitsuba_render(o("warm.exr"), args.width, args.height, args.spp, 1)
    mitsuba_seconds = min(mitsuba_render(o("mitsuba-timed.exr"), args.width, args.height, args.spp, s) for s in (2, 3))
    mitsuba_sps = args.width * args.height * args.spp / mitsuba_seconds
    quadray_sps = quadray_render(args.quadray, o("quadray-timed"), args.width, args.height, args.spp, 1, bench=True)

    # Error per sample, each against its own reference.
    w, h = args.err_width, args.err_height
    mitsuba_render(o("mitsuba-ref.exr"), w, h, args.ref_spp, 1000)
    quadray_render(args.quadray, o("quadray-ref"), w, h, args.ref_spp, 1000)
    errors = {}
    for spp in (16, 64):
        m, q = [], []
        for seed in range(1, args.seeds + 1):
            mitsuba_render(o(f"mitsuba-{spp}-{seed}.exr"), w, h, spp, seed)
            quadray_render(args.quadray, o(f"quadray-{spp}-{seed}"), w, h, spp, seed)
            m.append(relmse(args.quadray, o("mitsuba-ref.exr"), o(f"mitsuba-{spp}-{seed}.exr")))
            q.append(relmse(args.quadray, o("quadray-ref.exr"), o(f"quadray-{spp}-{seed}.exr")))
        errors[spp] = {"mitsuba": sum(m) / len(m), "quadray": sum(q) / len(q)}

    result = {
        "command": "python3 scripts/mitsuba_side_by_side.py " + " ".join(
            f"--{k.replace('_', '-')} {v}" for k, v in vars(args).items()),
        "mitsuba": mi.__version__ + " llvm_ad_rgb, path, independent, box filter",
        "samples_per_second": {"quadray": quadray_sps, "mitsuba": mitsuba_sps, "quadray/mitsuba": quadray_sps / mitsuba_sps},
        "relmse": errors,
    }
    with open(o("side_by_side.json"), "w") as f:
        json.dump(result, f, indent=2)
    print(f"samples/s at {args.width}x{args.height}, {args.spp} spp: quadray {quadray_sps:.0f}, "
          f"Mitsuba {mitsuba_sps:.0f}, quadray/Mitsuba {quadray_sps / mitsuba_sps:.3f}")
    for spp, e in errors.items():
        print(f"relMSE at {spp} spp ({w}x{h}, {args.seeds} seeds, against each one's {args.ref_spp}-spp reference): "
              f"quadray {e['quadray']:.5f}, Mitsuba {e['mitsuba']:.5f}, quadray/Mitsuba {e['quadray'] / e['mitsuba']:.3f}")


if __name__ == "__main__":
    main()
