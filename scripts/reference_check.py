#!/usr/bin/env python3
"""Checks a reference made by the consistent estimators (the passes at a high
spp) against a brute-force render where brute force has converged.

A pixel of the brute-force render counts as converged when its largest single
sample (the `max_sample.Y` AOV) is under FRACTION of the pixel's total (spp x
its mean luminance): no one path decides it. Over those pixels the script
prints the relative MSE between the two renders and the ratio of their mean
radiance, and how many pixels qualify.

Usage: pip install numpy OpenEXR;
  scripts/reference_check.py REFERENCE.exr BRUTE.exr BRUTE_SPP [FRACTION]
(FRACTION defaults to 0.01). Used for results/caustics/README.md (issue 30).
"""
import sys

import numpy as np
import OpenEXR


def load(path):
    channels = OpenEXR.File(path).channels()
    rgb = np.asarray(channels["RGB"].pixels, dtype=np.float64)
    largest = np.asarray(channels["max_sample.Y"].pixels, dtype=np.float64) if "max_sample.Y" in channels else None
    return rgb, largest


def main():
    reference, _ = load(sys.argv[1])
    brute, largest = load(sys.argv[2])
    spp = float(sys.argv[3])
    fraction = float(sys.argv[4]) if len(sys.argv) > 4 else 0.01
    luminance = brute @ np.array([0.2126, 0.7152, 0.0722])
    converged = largest < fraction * spp * np.maximum(luminance, 1e-6)
    err = ((brute - reference) ** 2 / (reference**2 + 1e-2)).mean(-1)
    ratio = brute[converged].mean() / reference[converged].mean()
    print(
        f"{converged.sum()} of {converged.size} pixels converged (largest sample < {fraction} of the pixel); "
        f"there: relative MSE {err[converged].mean():.5f}, mean radiance brute / reference {ratio:.4f}; "
        f"everywhere: relative MSE {err.mean():.5f}"
    )


if __name__ == "__main__":
    main()
