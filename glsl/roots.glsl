// First root of a polynomial of degree <= 6 on an interval, by root isolation:
// the roots of p' split the interval into pieces where p is monotonic, each
// holding at most one root, found by Newton's method safeguarded by bisection.
// C. Yuksel, "High-Performance Polynomial Root Finding for Graphics", HPG 2022.
// The f64 twin is src/geometry/poly.rs.
#ifndef ROOTS_GLSL
#define ROOTS_GLSL

const float NO_ROOT = 3.402823e38;

// d[k][j]: coefficient j of the k-th derivative.
float evalPoly(float d[7][7], int k, int deg, float x) {
    float v = 0.0;
    for (int j = deg - k; j >= 0; --j) v = v * x + d[k][j];
    return v;
}

// Root of derivative k in [x0, x1], where it is monotonic and v0 = value at x0
// has the opposite sign of its value at x1.
float solveBracket(float d[7][7], int k, int deg, float x0, float x1, float v0) {
    bool rising = v0 < 0.0;
    float x = 0.5 * (x0 + x1);
    for (int it = 0; it < 48; ++it) {
        float v = evalPoly(d, k, deg, x);
        if (v == 0.0) return x;
        if ((v < 0.0) == rising) x0 = x; else x1 = x;
        float slope = evalPoly(d, k + 1, deg, x);
        float nx = x - v / slope;
        x = (slope != 0.0 && nx > x0 && nx < x1) ? nx : 0.5 * (x0 + x1);
        if (x1 - x0 <= 2.0e-7 * max(abs(x0), abs(x1))) break;
    }
    return x;
}

// Smallest root in [lo, hi] of the polynomial c (lowest degree first), where
// it is zero or changes sign; NO_ROOT when there is none.
float firstRoot(float c[7], float lo, float hi) {
    int deg = 6;
    while (deg > 0 && c[deg] == 0.0) --deg;
    if (deg == 0) return c[0] == 0.0 ? lo : NO_ROOT;
    float d[7][7];
    for (int j = 0; j <= 6; ++j) d[0][j] = c[j];
    for (int k = 1; k <= deg; ++k)
        for (int j = 0; j <= deg - k; ++j) d[k][j] = d[k - 1][j + 1] * float(j + 1);

    // splits: sorted roots of derivative k+1 in (lo, hi).
    float splits[6];
    int ns = 0;
    for (int k = deg - 1; k >= 0; --k) {
        float roots[6];
        int nr = 0;
        float x0 = lo;
        float v0 = evalPoly(d, k, deg, x0);
        if (v0 == 0.0) {
            if (k == 0) return lo;
            roots[nr++] = lo;
        }
        for (int i = 0; i <= ns; ++i) {
            float x1 = i < ns ? splits[i] : hi;
            float v1 = evalPoly(d, k, deg, x1);
            float r = NO_ROOT;
            if (v1 == 0.0) r = x1;
            else if (v0 != 0.0 && ((v0 < 0.0) != (v1 < 0.0))) r = solveBracket(d, k, deg, x0, x1, v0);
            if (r != NO_ROOT) {
                if (k == 0) return r;
                if (nr < 6 && (nr == 0 || roots[nr - 1] != r)) roots[nr++] = r;
            }
            x0 = x1;
            v0 = v1;
        }
        ns = nr;
        for (int i = 0; i < 6; ++i) splits[i] = roots[i];
    }
    return NO_ROOT;
}

#endif
