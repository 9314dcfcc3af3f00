#!/usr/bin/env python3
"""quadray against Mitsuba 3 on the paper's scenes, at equal quality (issue 44).

For each scene: `quadray export` turns it into meshes, maps and JSON
(scripts/mitsuba_scene.py makes the Mitsuba scene of them); Mitsuba renders
a long reference (REF_SPP) and its 256-spp image, whose relMSE against the
reference is the target error; quadray renders at 1, 2, 4, ... spp, with the
paper's methods ("best": covariance prefiltering, the caustic and volume
passes where the scene needs them) and with
`--filter none --brute-force` (the path tracer alone), until its relMSE against the same reference reaches the
target (the first count of the doubling that reaches it: an upper bound on
quadray's time, by up to 2x). quadray's own long render is compared with the reference too
("agreement"): the error floor that the two renderers' differences (the
mesh, texture lookups) leave.

Times: Mitsuba's mi.render after an untimed warm-up render of the same scene
(its kernels compiled), quadray's GPU seconds of the render (the `wrote ...`
line, caustic and volume passes included) after an untimed warm-up process
(lavapipe's shader cache filled). relMSE by `quadray compare` on linear
radiance.

Writes OUT/results.json (one object per scene: scene, mitsuba_integrator,
target_relmse, mitsuba_s, quadray_s, time_ratio = quadray_s / mitsuba_s,
and the curves) and OUT/results.md.

Writes OUT/SCENE.png: Mitsuba at 256 spp | quadray best | quadray plain |
the reference. Each scene's working files (the export, every EXR) stay in
OUT/SCENE/ (ignored by git).

Usage: pip install mitsuba==3.9.1 numpy; apt-get install libllvm19; cargo build --release;
  python3 scripts/mitsuba_paper_scenes.py [--scenes a.toml b.toml] [--width 256 --height 192]
"""

import json
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
from mitsuba_scene import Unsupported, arguments, compare, mitsuba_dict  # noqa: E402

import mitsuba as mi  # noqa: E402

PAPER_SCENES = ["scenes/curved_mirrors.toml", "scenes/glints.toml", "scenes/tests/lens.toml",
                "scenes/tests/lens_fog.toml", "scenes/glass_vessel.toml"]


def mitsuba_render(export, path, w, h, spp, seed, integrator):
    scene = mi.load_dict(mitsuba_dict(export, w, h, spp, seed, integrator))
    start = time.perf_counter()
    image = mi.render(scene, spp=spp, seed=seed)
    mi.Bitmap(image).write(path)  # forces the evaluation before the clock stops
    return time.perf_counter() - start


def quadray_render(quadray, scene, path, w, h, spp, seed, extra):
    cmd = [quadray, "render", scene, "--width", str(w), "--height", str(h), "--spp", str(spp), "--seed",
           str(seed), "--no-denoise", "-o", path] + extra
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    return float(re.search(r"spp, ([0-9.]+) s on ", out).group(1))


def side_by_side(exrs, png):
    import numpy as np

    row = np.concatenate([np.array(mi.Bitmap(p))[..., :3] for p in exrs], axis=1).astype(np.float32)
    mi.Bitmap(row).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True).write(png)


def run_scene(args, scene):
    name = os.path.splitext(os.path.basename(scene))[0]
    out = os.path.join(args.out, name)
    export = os.path.join(out, "export")
    os.makedirs(out, exist_ok=True)
    o = lambda f: os.path.join(out, f)  # noqa: E731
    w, h = args.width, args.height
    subprocess.run([args.quadray, "export", scene, "-o", export, "--cells", str(args.cells)], check=True)
    integrator = args.integrator
    try:
        mitsuba_dict(export, w, h, 1, 1, integrator)
    except Unsupported as e:
        print(f"{name}: not compared: {e}", flush=True)
        return {"scene": scene, "unsupported": str(e)}
    ref_s = mitsuba_render(export, o("mitsuba-reference.exr"), w, h, args.ref_spp, 1000, integrator)
    # Untimed, the timed render itself: Dr.Jit compiles its kernels.
    mitsuba_render(export, o("warm.exr"), w, h, 256, 1, integrator)
    mitsuba_s = mitsuba_render(export, o("mitsuba-256.exr"), w, h, 256, 1, integrator)
    target, mitsuba_flip = compare(args.quadray, o("mitsuba-reference.exr"), o("mitsuba-256.exr"))
    print(f"{name}: Mitsuba reference {args.ref_spp} spp in {ref_s:.1f} s; 256 spp: relMSE {target:.5f} "
          f"FLIP {mitsuba_flip:.4f} in {mitsuba_s:.2f} s", flush=True)
    quadray_render(args.quadray, scene, o("warm"), w, h, 1, 1, [])
    quadray_render(args.quadray, scene, o("quadray-long"), w, h, args.quadray_ref_spp, 1000, ["--filter", "none"])
    agreement, agreement_flip = compare(args.quadray, o("mitsuba-reference.exr"), o("quadray-long.exr"))
    print(f"{name}: quadray {args.quadray_ref_spp} spp (filter none) against Mitsuba's reference: relMSE "
          f"{agreement:.5f} FLIP {agreement_flip:.4f}", flush=True)
    # "best": the paper's methods: covariance prefiltering (a scene without
    # maps renders as with none), the caustic and volume passes where the
    # scene needs them; "plain": the path tracer alone.
    settings = {"best": ["--filter", "covariance"], "plain": ["--filter", "none", "--brute-force"]}
    curves, reached = {}, {}
    for label, extra in settings.items():
        # Untimed: lavapipe compiles this variant's shaders.
        quadray_render(args.quadray, scene, o("warm"), w, h, 1, 1, extra)
        curves[label] = []
        spp = 1
        while spp <= args.max_spp:
            seconds = quadray_render(args.quadray, scene, o(f"quadray-{label}-{spp}"), w, h, spp, 1, extra)
            e, flip = compare(args.quadray, o("mitsuba-reference.exr"), o(f"quadray-{label}-{spp}.exr"))
            curves[label].append({"spp": spp, "seconds": seconds, "relmse": e, "flip": flip})
            print(f"{name}: quadray {label} {spp} spp: relMSE {e:.5f} FLIP {flip:.4f} in {seconds:.2f} s", flush=True)
            if e <= target:
                reached[label] = {"spp": spp, "seconds": seconds, "relmse": e, "flip": flip}
                break
            spp *= 2
    # The images side by side (sRGB PNG): Mitsuba at 256 spp, quadray with
    # its best settings at the sample count that reached the target (or its
    # last), quadray plain likewise, and the reference.
    shown = [o("mitsuba-256.exr")]
    for label in settings:
        spp = reached.get(label, curves[label][-1])["spp"]
        shown.append(o(f"quadray-{label}-{spp}.exr"))
    shown.append(o("mitsuba-reference.exr"))
    side_by_side(shown, os.path.join(args.out, f"{name}.png"))
    best = min((r["seconds"] for r in reached.values()), default=None)
    return {
        "scene": scene,
        "mitsuba_integrator": mitsuba_dict(export, w, h, 1, 1, integrator)["integrator"]["type"],
        "target_relmse": target,
        "mitsuba_flip": mitsuba_flip,
        "mitsuba_s": mitsuba_s,
        "quadray_s": best,
        "time_ratio": None if best is None else best / mitsuba_s,
        "agreement_relmse": agreement,
        "agreement_flip": agreement_flip,
        "quadray_reached": reached,
        "quadray_curves": curves,
        "size": [w, h],
        "mitsuba_reference_spp": args.ref_spp,
        "mesh_cells": args.cells,
    }


def main():
    ap = arguments(__doc__, "results/mitsuba/paper", 256, 192, 4096)
    ap.add_argument("--scenes", nargs="+", default=PAPER_SCENES)
    ap.add_argument("--quadray-ref-spp", type=int, default=512)
    ap.add_argument("--max-spp", type=int, default=512)
    ap.add_argument("--cells", type=int, default=512)
    ap.add_argument("--integrator", default="path")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    results = [run_scene(args, s) for s in args.scenes]
    command = "python3 scripts/mitsuba_paper_scenes.py " + " ".join(
        f"--{k.replace('_', '-')} {' '.join(v) if isinstance(v, list) else v}" for k, v in vars(args).items())
    machine = subprocess.run(["uname", "-srm"], capture_output=True, text=True).stdout.strip()
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump({"command": command, "machine": machine, "mitsuba": mi.__version__ + " llvm_ad_rgb",
                   "scenes": results}, f, indent=2)
    lines = [f"`{command}` ({machine}; Mitsuba {mi.__version__} llvm_ad_rgb; quadray on lavapipe)", "",
             "| scene | Mitsuba 256 spp: relMSE (FLIP) | Mitsuba s | quadray s to that relMSE (its FLIP) | ratio "
             "| quadray long vs reference: relMSE (FLIP) |",
             "|---|---:|---:|---:|---:|---:|"]
    for r in results:
        if "unsupported" in r:
            lines.append(f"| {r['scene']} | not compared: {r['unsupported']} | | | | |")
            continue
        fastest = min(r["quadray_reached"].items(), key=lambda kv: kv[1]["seconds"], default=None)
        q = "not reached" if fastest is None else \
            f"{fastest[1]['seconds']:.2f} ({fastest[0]}, {fastest[1]['spp']} spp; {fastest[1]['flip']:.4f})"
        ratio = "" if r["time_ratio"] is None else f"{r['time_ratio']:.2f}"
        lines.append(f"| {r['scene']} | {r['target_relmse']:.5f} ({r['mitsuba_flip']:.4f}) | {r['mitsuba_s']:.2f} | "
                     f"{q} | {ratio} | {r['agreement_relmse']:.5f} ({r['agreement_flip']:.4f}) |")
    with open(os.path.join(args.out, "results.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
