// First root of a polynomial of degree <= 6 on an interval, isolated in the
// Bernstein basis: by Descartes' rule of signs for Bernstein coefficients, an
// interval whose coefficients do not change sign holds no root, and one
// whose coefficients change sign exactly once holds exactly one. Intervals are
// halved left first (the Vincent-Collins-Akritas / Bezier-subdivision scheme,
// see e.g. Mourrain & Pavone, "Subdivision methods for solving polynomial
// equations", J. Symb. Comp. 2009), so the first isolated interval holds the
// first root, which Newton's method safeguarded by bisection then finds.
//
// All loops have constant bounds so that the arrays stay in registers. The
// CPU reference (src/model/geometry/poly.rs, f64) isolates roots differently (by
// the roots of the derivatives), so the two check each other.
#ifndef ROOTS_GLSL
#define ROOTS_GLSL

#include "common.glsl"

// Deepest halving: intervals of 2^-14 of the piece.
const uint MAX_LEVEL = 14u;

// C(i, j) / C(6, j): power coefficients on [0, 1] to Bernstein coefficients.
const float POWER_TO_BERNSTEIN[7][7] = float[7][7](
    float[7](1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    float[7](1.0, 1.0 / 6.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    float[7](1.0, 2.0 / 6.0, 1.0 / 15.0, 0.0, 0.0, 0.0, 0.0),
    float[7](1.0, 3.0 / 6.0, 3.0 / 15.0, 1.0 / 20.0, 0.0, 0.0, 0.0),
    float[7](1.0, 4.0 / 6.0, 6.0 / 15.0, 4.0 / 20.0, 1.0 / 15.0, 0.0, 0.0),
    float[7](1.0, 5.0 / 6.0, 10.0 / 15.0, 10.0 / 20.0, 5.0 / 15.0, 1.0 / 6.0, 0.0),
    float[7](1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0));

// Value of c (lowest degree first) at x; its derivative in `slope`.
float evalPoly(float c[7], float x, out float slope) {
    float v = c[6];
    slope = 0.0;
    for (int j = 5; j >= 0; --j) {
        slope = slope * x + v;
        v = v * x + c[j];
    }
    return v;
}

// Bernstein coefficients on t in [0, 1] of c(lo + (hi - lo) t).
void toBernstein(float c[7], float lo, float hi, out float b[7]) {
    float a[7] = c;
    // Taylor shift to lo (repeated synthetic division).
    for (int i = 0; i < 6; ++i)
        for (int j = 5; j >= i; --j) a[j] += lo * a[j + 1];
    float w = hi - lo, wj = 1.0;
    for (int j = 0; j < 7; ++j) { a[j] *= wj; wj *= w; }
    for (int i = 0; i < 7; ++i) {
        float s = 0.0;
        for (int j = 0; j < 7; ++j) s += POWER_TO_BERNSTEIN[i][j] * a[j];
        b[i] = s;
    }
}

// Bernstein coefficients on [t0, t1] from those on [0, 1] (de Casteljau:
// the left part at t1, then the right part of that at t0 / t1).
void restrictBernstein(inout float b[7], float t0, float t1) {
    for (int r = 1; r < 7; ++r)
        for (int i = 6; i >= r; --i) b[i] = mix(b[i - 1], b[i], t1);
    float s = t0 / t1;
    for (int r = 1; r < 7; ++r)
        for (int i = 0; i < 7 - r; ++i) b[i] = mix(b[i], b[i + 1], s);
}

int signChanges(float b[7]) {
    int n = 0;
    float last = b[0];
    for (int i = 1; i < 7; ++i) {
        if (b[i] != 0.0) {
            if (last != 0.0 && (last < 0.0) != (b[i] < 0.0)) ++n;
            last = b[i];
        }
    }
    return n;
}

// The root of c in [x0, x1], where c changes sign once.
float solveBracket(float c[7], float x0, float x1) {
    float slope;
    float v0 = evalPoly(c, x0, slope);
    if (v0 == 0.0) return x0;
    bool rising = v0 < 0.0;
    float x = 0.5 * (x0 + x1);
    for (int it = 0; it < 40; ++it) { LOOP_EDGE();
        float v = evalPoly(c, x, slope);
        if (v == 0.0) return x;
        if ((v < 0.0) == rising) x0 = x; else x1 = x;
        float nx = x - v / slope;
        float next = (slope != 0.0 && nx > x0 && nx < x1) ? nx : 0.5 * (x0 + x1);
        if (abs(next - x) <= 1e-7 * max(abs(x0), abs(x1)) || x1 - x0 <= 1e-7 * max(abs(x0), abs(x1))) return next;
        x = next;
    }
    return x;
}

// Smallest root in [lo, hi] of the polynomial c (lowest degree first) where it
// changes sign or is zero at an interval end; NO_ROOT when there is none.
// A root of even multiplicity (a tangent ray) is not reported.
float firstRoot(float c[7], float lo, float hi) {
    float whole[7];
    toBernstein(c, lo, hi, whole);
    float w = hi - lo;
    // The current interval is [idx, idx + 1] / 2^level of [0, 1]; the walk is
    // a depth-first, left-first traversal of the binary subdivision tree.
    uint level = 0u, idx = 0u;
    for (int it = 0; it < 160; ++it) { LOOP_EDGE();
        float size = 1.0 / float(1u << level);
        float t0 = float(idx) * size, t1 = t0 + size;
        float b[7] = whole;
        if (level > 0u) restrictBernstein(b, t0, t1);
        if (b[0] == 0.0) return lo + w * t0;
        int v = signChanges(b);
        bool descend = v > 1 && level < MAX_LEVEL;
        if (!descend && v > 0 && (b[0] < 0.0) != (b[6] < 0.0)) {
            return solveBracket(c, lo + w * t0, lo + w * t1);
        }
        if (descend) {
            ++level;
            idx <<= 1u;
            continue;
        }
        // No root here (or only a touching one): go to the next interval.
        while ((idx & 1u) == 1u) { LOOP_EDGE(); idx >>= 1u; --level; }
        if (level == 0u) return NO_ROOT;
        idx += 1u;
    }
    return NO_ROOT;
}

#endif
