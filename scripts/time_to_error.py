#!/usr/bin/env python3
"""How long quadray takes to reach a relMSE target against its own long
render (issue 44: the glass vessel at 512x384, relMSE 0.05 within 10 minutes).

Renders the reference (REF_FLAGS at REF_SPP; `--reference EXR` reuses one),
then the test setting (FLAGS) at 1, 2, 4, ... spp, each compared with the
reference by `quadray compare` (relMSE on linear radiance, FLIP), until the
relMSE reaches TARGET or a render takes longer than LIMIT seconds. Times are
quadray's GPU seconds (the `wrote` line: caustic and volume passes
included), after an untimed warm-up render of each setting (lavapipe
compiles its shaders). Writes OUT/time_to_error.json with the command and
every point.

Usage: python3 scripts/time_to_error.py SCENE --width 512 --height 384
    --ref-spp 1024 --ref-flags='--filter covariance --caustic-rays 262144 ...'
    --flags='--filter covariance ...' --target 0.05 --limit 600 --out DIR
"""

import argparse
import json
import os
import shlex
import sys

sys.path.insert(0, os.path.dirname(__file__))
from quadray_cli import compare, quadray_render  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--quadray", default="target/release/quadray")
    ap.add_argument("--out", required=True)
    ap.add_argument("--width", type=int, default=512)
    ap.add_argument("--height", type=int, default=384)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--ref-flags", default="--filter covariance")
    ap.add_argument("--reference", help="an existing reference EXR (then REF_SPP and REF_FLAGS only describe it)")
    ap.add_argument("--flags", default="--filter covariance")
    ap.add_argument("--target", type=float, default=0.05)
    ap.add_argument("--limit", type=float, default=600.0)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    o = lambda f: os.path.join(args.out, f)  # noqa: E731
    w, h = args.width, args.height
    reference = args.reference
    ref_s = None
    if reference is None:
        reference = o("reference.exr")
        ref_s = quadray_render(args.quadray, args.scene, o("reference"), w, h, args.ref_spp, 1000,
                               shlex.split(args.ref_flags))
        print(f"reference: {args.ref_spp} spp in {ref_s:.1f} s", flush=True)
    flags = shlex.split(args.flags)
    quadray_render(args.quadray, args.scene, o("warm"), w, h, 1, 1, flags)
    points, reached, spp = [], None, 1
    while True:
        seconds = quadray_render(args.quadray, args.scene, o(f"test-{spp}"), w, h, spp, 1, flags)
        e, flip = compare(args.quadray, reference, o(f"test-{spp}.exr"))
        points.append({"spp": spp, "seconds": seconds, "relmse": e, "flip": flip})
        print(f"{spp} spp: relMSE {e:.5f} FLIP {flip:.4f} in {seconds:.2f} s", flush=True)
        if e <= args.target:
            reached = points[-1]
            break
        if seconds > args.limit:
            break
        spp *= 2
    command = "python3 scripts/time_to_error.py " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    with open(o("time_to_error.json"), "w") as f:
        json.dump({"command": command, "scene": args.scene, "size": [w, h], "reference_spp": args.ref_spp,
                   "reference_flags": args.ref_flags, "reference_s": ref_s, "flags": args.flags,
                   "target_relmse": args.target, "limit_s": args.limit, "reached": reached, "points": points},
                  f, indent=2)
    print("reached" if reached else "not reached", json.dumps(reached))


if __name__ == "__main__":
    main()
