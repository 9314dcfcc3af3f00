#!/usr/bin/env python3
"""Prints the README's prefiltering headline table from results/filtering/headline.json.

Usage: python3 scripts/headline_table.py [results/filtering/headline.json]

One row per scene and target: the texture share, the time-to-equal-quality
speed-up of each filtered mode over `none` on the whole image and on the
texture mask, covariance against ray cones on the mask (the ratio of their
speed-ups), and the cost per sample over `none`. "not reached" where a mode
does not reach the target at equal quality within the measured spp.
"""
import json
import sys


def cell(value, lower_bound=False):
    if value is None:
        return "not reached"
    return f"{'≥ ' if lower_bound else ''}{value:.2f}x"


def ratio(cov, cones, cov_bound, cones_bound):
    """Covariance's speed-up over ray cones' (both over `none`)."""
    if cov is None:
        return "cov. not reached"
    if cones is None:
        return "cones not reached"
    if cov_bound and cones_bound:
        return "both at 1 spp"
    if cones_bound:
        return f"≤ {cov / cones:.2f}x"
    if cov_bound:
        return f"≥ {cov / cones:.2f}x"
    return f"{cov / cones:.2f}x"


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "results/filtering/headline.json"
    with open(path) as f:
        entries = json.load(f)
    print(
        "| scene | texture share | target | ray-cones | covariance | ray-cones, mask | covariance, mask "
        "| covariance / ray cones, mask | cost per sample (cones, cov.) |"
    )
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|")
    for e in entries:
        s, m, c = e["speedup_vs_none"], e["speedup_vs_none_masked"], e["cost_per_sample"]
        lb = e.get("speedup_is_lower_bound", {})
        counts = "" if e["counts"] else " (share < 0.9)"
        print(
            f"| `{e['scene']}`{counts} | {e['texture_share']:.3f} | {e['target']} "
            f"| {cell(s.get('ray-cones'), lb.get('ray-cones', False))} "
            f"| **{cell(s.get('covariance'), lb.get('covariance', False))}** "
            f"| {cell(m.get('ray-cones'), lb.get('ray-cones', False))} "
            f"| {cell(m.get('covariance'), lb.get('covariance', False))} "
            f"| {ratio(m.get('covariance'), m.get('ray-cones'), lb.get('covariance', False), lb.get('ray-cones', False))} "
            f"| {c.get('ray-cones', 0):.2f}, {c.get('covariance', 0):.2f} |"
        )


if __name__ == "__main__":
    main()
