#!/usr/bin/env python3
"""quadray against Mitsuba 3 on the paper's scenes, at equal quality (issue 44).

For each scene: `quadray export` turns it into meshes, maps and JSON
(scripts/mitsuba_scene.py makes the Mitsuba scene of them); Mitsuba renders
a long reference (REF_SPP) and its 256-spp image, whose relMSE against the
reference is the target error (relMSE on linear radiance; its FLIP the
second target); quadray renders at 1, 2, 4, ... spp until it reaches both
(or MAX_SPP), with the paper's methods ("best-PRESET": covariance
prefiltering, the caustic and volume passes where the scene needs them, at
the pass budget of each quality preset, docs/presets.md) and with
`--filter none --brute-force` ("plain": the path tracer alone); between the
last count short of the relMSE target and the first that reaches it, it
bisects to within an eighth of that count. quadray's time is the fastest
measured render that reached the target (quadray_setting says which);
quadray_flip_s likewise for Mitsuba's FLIP (the first count measured that
reaches it, not bisected: an upper bound by up to 2x). One seed per count:
where fireflies drive the relMSE, the first count below the target is
partly luck. quadray's own long render is
compared with the reference too ("agreement"): the error floor that the two
renderers' differences (the mesh, texture lookups) and the reference's own
noise leave.

Times (the median of TIMINGS runs of the same render): Mitsuba's mi.render
after an untimed warm-up render of the same scene (its kernels compiled),
quadray's GPU seconds of the render (the `wrote ...`
line, caustic and volume passes included) after an untimed warm-up process
(lavapipe's shader cache filled). relMSE by `quadray compare` on linear
radiance.

Writes OUT/results.json (one object per scene: scene, mitsuba_integrator,
target_relmse, mitsuba_s, quadray_s, time_ratio = quadray_s / mitsuba_s,
quadray_setting, the FLIP figures, each setting's flags and curve) and
OUT/results.md.

Writes OUT/SCENE.png: Mitsuba at 256 spp | quadray's fastest best-PRESET | quadray plain |
the reference. Each scene's working files (the export, every EXR) stay in
OUT/SCENE/ (ignored by git).

Usage: pip install mitsuba==3.9.1 numpy; apt-get install libllvm19; cargo build --release;
  python3 scripts/mitsuba_paper_scenes.py [--scenes a.toml b.toml] [--width 256 --height 192]
"""

import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
from mitsuba_scene import Unsupported, arguments, mitsuba_dict, render  # noqa: E402
from quadray_cli import command_line, compare, quadray_render  # noqa: E402

import mitsuba as mi  # noqa: E402

# The caustic and volume passes' budgets of the presets (docs/presets.md):
# caustic rays per light sample, light samples, volume rays per pixel and
# sample.
PASS_BUDGETS = {
    "preview": ["--caustic-rays", "16384", "--caustic-light-samples", "1", "--volume-samples", "1"],
    "interactive": ["--caustic-rays", "65536", "--caustic-light-samples", "4", "--volume-samples", "1"],
    "final": ["--caustic-rays", "262144", "--caustic-light-samples", "8", "--volume-samples", "2"],
}

# How many times each timed render runs (the median is reported): the
# 256-spp Mitsuba render, and each quadray render that reached a target.
TIMINGS = 3

PAPER_SCENES = ["scenes/curved_mirrors.toml", "scenes/glints.toml", "scenes/tests/lens.toml",
                "scenes/tests/lens_fog.toml", "scenes/glass_vessel.toml"]


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
        scene_dict = mitsuba_dict(export, w, h, 256, 1, integrator)
    except Unsupported as e:
        print(f"{name}: not compared: {e}", flush=True)
        return {"scene": scene, "unsupported": str(e)}
    ref_s = render(mi.load_dict(mitsuba_dict(export, w, h, args.ref_spp, 1000, integrator)),
                   o("mitsuba-reference.exr"), args.ref_spp, 1000)
    # Loaded once (meshes of millions of triangles) for the 256-spp renders:
    # untimed, the timed render itself (Dr.Jit compiles its kernels), then
    # the timed ones.
    loaded = mi.load_dict(scene_dict)
    render(loaded, o("warm.exr"), 256, 1)
    mitsuba_runs = [render(loaded, o("mitsuba-256.exr"), 256, 1) for _ in range(TIMINGS)]
    mitsuba_s = statistics.median(mitsuba_runs)
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
    # scene needs them, at each preset's pass budget (docs/presets.md; the
    # scene's own depth and spp search kept); "plain": the path tracer alone.
    warm = quadray_render(args.quadray, scene, o("warm"), w, h, 1, 1, ["--filter", "covariance"], log=True)
    has_passes = "caustics:" in warm or "volume:" in warm
    settings = {f"best-{p}": ["--filter", "covariance"] + (budget if has_passes else [])
                for p, budget in PASS_BUDGETS.items() if has_passes or p == "interactive"}
    settings["plain"] = ["--filter", "none", "--brute-force"]
    curves, reached, reached_flip = {}, {}, {}
    for label, extra in settings.items():
        # Untimed: lavapipe compiles this variant's shaders.
        quadray_render(args.quadray, scene, o("warm"), w, h, 1, 1, extra)
        points = {}

        def point(spp):
            if spp not in points:
                exr = o(f"quadray-{label}-{spp}")
                seconds = quadray_render(args.quadray, scene, exr, w, h, spp, 1, extra)
                e, flip = compare(args.quadray, o("mitsuba-reference.exr"), exr + ".exr")
                points[spp] = {"spp": spp, "seconds": seconds, "relmse": e, "flip": flip}
                print(f"{name}: quadray {label} {spp} spp: relMSE {e:.5f} FLIP {flip:.4f} in {seconds:.2f} s",
                      flush=True)
            return points[spp]

        # Doubling until both Mitsuba's relMSE and its FLIP are reached (or
        # max_spp), then bisection between the last two counts around the
        # relMSE crossing, to within an eighth of the count: the reported
        # time is a measured render that reached the target.
        spp = 1
        while spp <= args.max_spp:
            p = point(spp)
            if p["relmse"] <= target and p["flip"] <= mitsuba_flip:
                break
            spp *= 2
        crossing = next((n for n in sorted(points) if points[n]["relmse"] <= target), None)
        if crossing is not None and crossing >= 4:
            lo, hi = crossing // 2, crossing
            while hi - lo > max(1, crossing // 8):
                mid = (lo + hi) // 2
                lo, hi = (lo, mid) if point(mid)["relmse"] <= target else (mid, hi)
            crossing = hi
        at_flip = next((n for n in sorted(points) if points[n]["flip"] <= mitsuba_flip), None)
        # The renders that reached a target timed TIMINGS times in all (the
        # same image each time): their median is the time reported.
        for n in {crossing, at_flip} - {None}:
            runs = [points[n]["seconds"]] + [
                quadray_render(args.quadray, scene, o(f"quadray-{label}-{n}"), w, h, n, 1, extra)
                for _ in range(TIMINGS - 1)]
            points[n].update(seconds=statistics.median(runs), runs=runs)
        curves[label] = [points[n] for n in sorted(points)]
        if crossing is not None:
            reached[label] = points[crossing]
        if at_flip is not None:
            reached_flip[label] = points[at_flip]
    fastest = min(reached, key=lambda k: reached[k]["seconds"], default=None)
    fastest_flip = min(reached_flip, key=lambda k: reached_flip[k]["seconds"], default=None)
    # The images side by side (sRGB PNG): Mitsuba at 256 spp, quadray with
    # the paper's methods at the render that reached the target fastest (or
    # the interactive budget's last), quadray plain likewise, and the
    # reference.
    shown = [o("mitsuba-256.exr")]
    for label in [fastest if fastest not in (None, "plain") else "best-interactive", "plain"]:
        spp = reached.get(label, curves[label][-1])["spp"]
        shown.append(o(f"quadray-{label}-{spp}.exr"))
    shown.append(o("mitsuba-reference.exr"))
    side_by_side(shown, os.path.join(args.out, f"{name}.png"))
    best = None if fastest is None else reached[fastest]["seconds"]
    best_flip = None if fastest_flip is None else reached_flip[fastest_flip]["seconds"]
    return {
        "scene": scene,
        "mitsuba_integrator": scene_dict["integrator"]["type"],
        "target_relmse": target,
        "mitsuba_flip": mitsuba_flip,
        "mitsuba_s": mitsuba_s,
        "mitsuba_runs": mitsuba_runs,
        "mitsuba_reference_s": ref_s,
        "quadray_s": best,
        "time_ratio": None if best is None else best / mitsuba_s,
        "quadray_setting": fastest,
        "quadray_flip_s": best_flip,
        "flip_time_ratio": None if best_flip is None else best_flip / mitsuba_s,
        "quadray_flip_setting": fastest_flip,
        "agreement_relmse": agreement,
        "agreement_flip": agreement_flip,
        "quadray_settings": settings,
        "quadray_reached": reached,
        "quadray_reached_flip": reached_flip,
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
    ap.add_argument("--update", action="store_true",
                    help="replace these scenes' entries in OUT/results.json, keep the others (each entry records "
                         "the command that made it)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    command = command_line("scripts/mitsuba_paper_scenes.py", args)
    machine = subprocess.run(["uname", "-srm"], capture_output=True, text=True).stdout.strip()
    made_by = {"command": command, "machine": machine, "mitsuba": mi.__version__ + " llvm_ad_rgb"}
    results = [dict(run_scene(args, s), **made_by) for s in args.scenes]
    path = os.path.join(args.out, "results.json")
    if args.update and os.path.exists(path):
        with open(path) as f:
            old = json.load(f)
        # (A file from before per-scene commands names one for all.)
        old_made_by = {k: old[k] for k in made_by if k in old}
        kept = [dict(old_made_by, **r) for r in old["scenes"] if r["scene"] not in args.scenes]
        order = {s: i for i, s in enumerate(PAPER_SCENES)}
        results = sorted(kept + results, key=lambda r: order.get(r["scene"], len(order)))
    with open(path, "w") as f:
        json.dump({"scenes": results}, f, indent=2)
    lines = ["Each scene's command and machine are in results.json; quadray on lavapipe, Mitsuba llvm_ad_rgb.", "",
             "| scene | Mitsuba 256 spp: relMSE (FLIP) | Mitsuba s | quadray s to that relMSE (setting, spp; its FLIP) "
             "| ratio | quadray s to that FLIP | ratio | quadray long vs reference: relMSE (FLIP) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        if "unsupported" in r:
            lines.append(f"| {r['scene']} | not compared: {r['unsupported']} | | | | | | |")
            continue
        q, ratio, qf, ratio_f = "not reached", "", "not reached", ""
        if r.get("quadray_setting") is not None:
            p = r["quadray_reached"][r["quadray_setting"]]
            q = f"{p['seconds']:.2f} ({r['quadray_setting']}, {p['spp']} spp; {p['flip']:.4f})"
            ratio = f"{r['time_ratio']:.2f}"
        if r.get("quadray_flip_setting") is not None:
            p = r["quadray_reached_flip"][r["quadray_flip_setting"]]
            qf = f"{p['seconds']:.2f} ({r['quadray_flip_setting']}, {p['spp']} spp)"
            ratio_f = f"{r['flip_time_ratio']:.2f}"
        lines.append(f"| {r['scene']} | {r['target_relmse']:.5f} ({r['mitsuba_flip']:.4f}) | {r['mitsuba_s']:.2f} | "
                     f"{q} | {ratio} | {qf} | {ratio_f} | {r['agreement_relmse']:.5f} ({r['agreement_flip']:.4f}) |")
    commands = sorted({r["command"] for r in results if "command" in r})
    lines += [""] + [f"`{c}`" for c in commands]
    with open(os.path.join(args.out, "results.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
