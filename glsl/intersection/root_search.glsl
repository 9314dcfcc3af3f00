// The first root of F' along a ray in one cell: the f32 search over the
// pieces where the active perturbations do not change, and its f64 refinement
// where f32 cannot decide. Included through intersect.glsl, which defines the
// INTERSECT_MODE specialisation constant it reads.
#ifndef ROOT_SEARCH_GLSL
#define ROOT_SEARCH_GLSL

#include "quadric.glsl"
#include "spec_constants.glsl"

// ---------------------------------------------------------------------------
// f64 refinement. The f32 search works on F' expanded around each piece's
// middle; where F' is tiny compared with its terms (a surface hugging a
// perturbation's support boundary, where f·Q³ has a near-triple root, or
// large form factors), f32 loses the sign of F' near the piece's ends and
// the position of flat roots. There, F' is evaluated directly from the
// quadrics in f64 (docs/stability.md, "Roots of multiplicity 2 and 3").
// ---------------------------------------------------------------------------

double quadricAt64(Quadric q, dvec3 p) {
    return double(q.a[0]) * p.x * p.x + double(q.a[1]) * p.y * p.y + double(q.a[2]) * p.z * p.z
         + 2.0 * (double(q.a[3]) * p.x * p.y + double(q.a[4]) * p.y * p.z + double(q.a[5]) * p.x * p.z)
         + double(q.b[0]) * p.x + double(q.b[1]) * p.y + double(q.b[2]) * p.z + double(q.c);
}

// F' at the object-frame point p, with every perturbation the cell lists.
double cellValue64(uint object, Cell cell, dvec3 p) {
    double v = quadricAt64(objects[object].base, p);
    [[dont_unroll]] for (uint i = 0; i < cell.count; ++i) { LOOP_EDGE();
        uint k = cellLists[cell.first + i];
        double q = quadricAt64(perturbationQuadric(k), p - dvec3(perturbationCentre(k)));
        if (q > 0.0) v += double(perturbations[k].f) * q * q * q;
    }
    return v;
}

// A root of F' along O + t D in [a, b], where fa = F'(a) and fb = F'(b)
// have opposite signs: regula falsi with the Illinois modification.
double bracketedRoot64(uint object, Cell cell, dvec3 O, dvec3 D, double a, double b, double fa, double fb) {
    int side = 0;
    double c = a;
    [[dont_unroll]] for (int it = 0; it < 60; ++it) { LOOP_EDGE();
        c = (a * fb - b * fa) / (fb - fa);
        if (!(c > a && c < b)) c = 0.5 * (a + b);
        double fc = cellValue64(object, cell, O + c * D);
        if (fc == 0.0 || b - a <= 1e-14 * max(abs(a), abs(b))) return c;
        if ((fc < 0.0) == (fb < 0.0)) {
            b = c;
            fb = fc;
            if (side == -1) fa *= 0.5;
            side = -1;
        } else {
            a = c;
            fa = fc;
            if (side == 1) fb *= 0.5;
            side = 1;
        }
    }
    return c;
}

// True when the polynomial c at x is within `tolerance` of the size of its
// terms there (1e-5: within a few f32 rounding errors, its sign unknown).
bool nearlyCancels(float c[7], float x, float tolerance) {
    float slope;
    float v = evalPoly(c, x, slope);
    float size = 0.0, xp = 1.0;
    for (int j = 0; j < 7; ++j) { LOOP_EDGE();
        size += abs(c[j]) * xp;
        xp *= abs(x);
    }
    return abs(v) <= tolerance * size;
}

bool signUncertain(float c[7], float x) {
    return nearlyCancels(c, x, 1e-5);
}

// The first root on the piece [ta, tb] of the ray O + t D (f64), given the
// f32 search's root tr (NO_ROOT when it found none) on the polynomial c
// expanded around tm: keeps tr where f64 confirms a sign change around it
// and f32 is well conditioned there, else finds the root again in f64, or
// drops it when f64 sees no sign change (see above). Returns a ray
// parameter, or NO_ROOT for none (parameters may be negative: far rays
// are searched from a point inside the cell, candidateFirstRoot).
double refineRoot64(uint object, Cell cell, dvec3 O, dvec3 D, double ta, double tb, double tm, float c[7], float tr) {
    bool startUncertain = signUncertain(c, float(ta - tm));
    double t = tm + double(tr);
    float step = 1e-3 * float(tb - ta);
    bool found = tr != NO_ROOT;
    if (found) {
        // Kept as f32 found it where it is well conditioned: Horner's
        // evaluation of c near tr errs by at most about 16 ε of the size of
        // its terms there (S = Σ|c_j| |tr|^j, ε = 2⁻²⁴ for degree 6), which
        // moves the root by 16 ε S / |c'(tr)|. Within 1e-5 of the piece it
        // is kept (ten times below the secondary rays' offset of 1e-4 of
        // the cell's width); a flatter root is settled in f64.
        float slope;
        evalPoly(c, tr, slope);
        float size = 0.0, xp = 1.0;
        for (int j = 0; j < 7; ++j) { LOOP_EDGE();
            size += abs(c[j]) * xp;
            xp *= abs(tr);
        }
        if (!startUncertain && 16.0 * 5.96e-8 * size <= 1e-5 * float(tb - ta) * abs(slope)) return t;
    } else if (!startUncertain && !signUncertain(c, float(tb - tm))) {
        return double(NO_ROOT);
    }
    bool flatRoot = found && (signUncertain(c, tr + step) || signUncertain(c, tr - step));
    // F' in f64 at the piece's start, its middle, either side of the f32
    // root (if any), and its end, in order along the ray. (One evaluation
    // site and one solver site below: the shader compiler inlines all of
    // this into every intersection call.)
    double w = 1e-3 * (tb - ta) + 1e-7 * abs(t);
    double rootLo = found ? max(ta, t - w) : tm, rootHi = found ? min(tb, t + w) : tm;
    double at[5] = double[5](ta, min(rootLo, tm), clamp(tm, rootLo, rootHi), max(rootHi, tm), tb);
    double v[5];
    [[dont_unroll]] for (int i = 0; i < 5; ++i) { LOOP_EDGE(); v[i] = cellValue64(object, cell, O + at[i] * D); }
    // The root is in the first interval whose ends differ in sign in f64:
    // the f32 root itself when that interval is the one around it and f32
    // is well conditioned there, else found again in f64. Looking at the
    // middle too catches pairs of roots that f32 cannot see and the ends
    // cannot tell apart: a ray through a wall-like bump at a large form
    // factor enters and leaves its support within one piece, each root
    // a hair inside it, where f32 has lost F' to rounding (and may report a
    // spurious root at the piece's start instead). No sign change in f64:
    // no root (f32 made it up).
    int lo = -1;
    [[dont_unroll]] for (int i = 0; i < 4 && lo < 0; ++i) { LOOP_EDGE();
        if ((v[i] < 0.0) != (v[i + 1] < 0.0)) lo = i;
    }
    if (lo < 0) return double(NO_ROOT);
    if (found && !flatRoot && at[lo] <= t && t <= at[lo + 1] && at[lo + 1] - at[lo] <= 2.0 * w) return t;
    if (v[lo] == 0.0) return at[lo];
    return bracketedRoot64(object, cell, O, D, at[lo], at[lo + 1], v[lo], v[lo + 1]);
}

// The part of the ray o + t d, t in [tlo, thi], inside `cell`'s box:
// [t0, t1]; false when the ray misses it.
bool clipToCell(Cell cell, vec3 o, vec3 d, float tlo, float thi, out float t0, out float t1) {
    vec3 inv = 1.0 / d;
    vec3 ta = (vec3(cell.lo[0], cell.lo[1], cell.lo[2]) - o) * inv;
    vec3 tb = (vec3(cell.hi[0], cell.hi[1], cell.hi[2]) - o) * inv;
    vec3 tmn = min(ta, tb), tmx = max(ta, tb);
    t0 = max(max(max(tmn.x, tmn.y), tmn.z), tlo);
    t1 = min(min(min(tmx.x, tmx.y), tmx.z), thi);
    return t0 <= t1;
}

// First t in [tlo, thi] (and inside the cell) where F' = 0 along o + t d, in
// the object's frame; NO_ROOT if none.
// The ray is (o, d); when `rebased`, (o64, d64) is the same ray in f64
// (o, d its rounding): the root search works around the segment's middle
// p = o + tc d, then formed in f64 and only then rounded to f32, so a ray from far away (1e4 object sizes) loses no more precision
// than one from nearby. `hitPoint` returns the root's object-space point,
// formed the same way.
float cellFirstRoot(uint object, uint cellIndex, vec3 o, vec3 d, bool rebased, dvec3 o64, dvec3 d64, float tlo,
                    float thi, out vec3 hitPoint) {
    Cell cell = cells[cellIndex];
    float t0, t1;
    if (!clipToCell(cell, o, d, tlo, thi, t0, t1)) return NO_ROOT;

    if (INTERSECT_MODE == INTERSECT_BOXES) {
        hitPoint = rebased ? vec3(o64 + double(t0) * d64) : o + t0 * d;
        return t0;
    }

    // Work in s = t - tc around the segment's middle.
    float tc = 0.5 * (t0 + t1);
    vec3 p = rebased ? vec3(o64 + double(tc) * d64) : o + tc * d;
    float s0 = t0 - tc, s1 = t1 - tc;
    vec3 base = quadricAlongRay(objects[object].base, p, d);
    if (INTERSECT_MODE == INTERSECT_BASE || cell.count == 0u) {
        float r = quadraticFirstRoot(base, s0, s1);
        hitPoint = p + r * d;
        return r == NO_ROOT ? NO_ROOT : tc + r;
    }

    // The steps: the segment inside the cell (clipToCell); the base
    // quadric's first root where no perturbation reaches the cell; else,
    // segment by segment, the perturbations that reach it and the pieces
    // between their supports' ends, each with F' as one polynomial: passed
    // by its interval bound, or searched for its first root (firstRoot) and
    // that root refined in f64 (refineRoot64).
    //
    // Gather the relevant perturbations. With more than MAX_RELEVANT of them
    // the segment is split in halves, each gathered again; where even a short
    // segment has more (many overlapping perturbations), the cell's whole list
    // is used, read from memory (slower, still exact). Inline: as a function
    // with the arrays as out parameters, the glass vessel's shaders took
    // 1.12x as long to compile cold on lavapipe (one run of two each).
    float segLo = s0;
    for (int split = 0; split < 64 && segLo < s1; ++split) { LOOP_EDGE();
        float segHi = s1;
        vec3 relQ[MAX_RELEVANT];
        float relF[MAX_RELEVANT];
        uint nrel = 0u;
        bool overflow = false;
        for (int attempt = 0; attempt < 8; ++attempt) { LOOP_EDGE();
            nrel = 0u;
            overflow = false;
            for (uint i = 0; i < cell.count; ++i) { LOOP_EDGE();
                uint k = cellLists[cell.first + i];
                vec3 q;
                if (perturbationOnSegment(k, p, d, segLo, segHi, q)) {
                    if (nrel == MAX_RELEVANT) { overflow = true; break; }
                    // Stored by constant indices (a select per slot): a
                    // store at the lane's own index nrel would keep the
                    // arrays in scratch memory on lavapipe (a scatter).
                    float f = perturbations[k].f;
                    [[unroll]] for (uint j = 0u; j < MAX_RELEVANT; ++j) {
                        if (j == nrel) {
                            relQ[j] = q;
                            relF[j] = f;
                        }
                    }
                    ++nrel;
                }
            }
            if (!overflow || attempt == 7) break;
            segHi = 0.5 * (segLo + segHi);
        }
        // With the whole list, the rest of the segment is searched at once
        // (halving further would gain nothing, and 64 splits of 1/128 each
        // would leave most of a long segment unsearched).
        bool all = overflow;
        if (all) {
            nrel = cell.count;
            segHi = s1;
        }

        // Walk the pieces of [segLo, segHi] between the breakpoints; on each,
        // F' is a polynomial of degree <= 6, expanded around the piece's own
        // middle so that its coefficients stay well conditioned in f32.
        float sa = segLo;
        for (uint piece = 0; piece <= 2u * nrel && sa < segHi; ++piece) { LOOP_EDGE();
            float sb = segHi;
            for (uint i = 0; i < nrel; ++i) { LOOP_EDGE();
                vec3 q = all ? perturbationAlongRay(cellLists[cell.first + i], p, d) : relQ[i];
                vec2 r = quadraticRoots(q);
                if (r.x > sa && r.x < sb) sb = r.x;
                if (r.y > sa && r.y < sb) sb = r.y;
            }
            float sm = 0.5 * (sa + sb);
            vec3 b = shiftQuadratic(base, sm);
            float c[7] = float[7](b.x, b.y, b.z, 0.0, 0.0, 0.0, 0.0);
            bool any = false;
            // Interval bounds of F' on the piece: the base quadratic's range
            // plus each active term's, f · [min q, max q]³ (q > 0 on the
            // whole piece). A range that excludes 0 by more than f32's
            // rounding of the terms (1e-5 of their size, as signUncertain)
            // holds no root: the piece is passed without root isolation.
            vec2 range = quadraticRange(b, sa - sm, sb - sm);
            float size = max(abs(range.x), abs(range.y));
            for (uint i = 0; i < nrel; ++i) { LOOP_EDGE();
                uint k = all ? cellLists[cell.first + i] : 0u;
                vec3 q = shiftQuadratic(all ? perturbationAlongRay(k, p, d) : relQ[i], sm);
                if (q.x > 0.0) {
                    float f = all ? perturbations[k].f : relF[i];
                    addCube(c, q, f);
                    any = true;
                    vec2 qr = max(quadraticRange(q, sa - sm, sb - sm), vec2(0.0));
                    vec2 cubes = f * qr * qr * qr;
                    range += vec2(min(cubes.x, cubes.y), max(cubes.x, cubes.y));
                    size += abs(f) * qr.y * qr.y * qr.y;
                }
            }
            if (any && (range.x > 1e-5 * size || range.y < -1e-5 * size)) {
                sa = sb;
                continue;
            }
            float r = any ? firstRoot(c, sa - sm, sb - sm) : quadraticFirstRoot(b, sa - sm, sb - sm);
            if (any) {
                // Ray parameters in f64: the ray is O + t D with t = tc + s.
                dvec3 O = rebased ? o64 : dvec3(o), D = rebased ? d64 : dvec3(d);
                double t64 = refineRoot64(object, cell, O, D, double(tc) + double(sa), double(tc) + double(sb),
                                          double(tc) + double(sm), c, r);
                if (t64 != double(NO_ROOT)) {
                    hitPoint = vec3(O + t64 * D);
                    return float(t64);
                }
            } else if (r != NO_ROOT) {
                hitPoint = p + (sm + r) * d;
                return tc + sm + r;
            }
            sa = sb;
        }
        segLo = segHi;
    }
    return NO_ROOT;
}

// ---------------------------------------------------------------------------
// Rays from far away. The hardware hands each candidate its object-frame ray
// in f32, and a ray parameter t is f32 too: one step of t is ~6e-8 · t, so
// seen from D object sizes, slab tests, breakpoints and roots are placed to
// ~6e-8 · D sizes (0.6 % of the object at 1e5, 6 % at 1e6), and a segment
// may overshoot its cell by that much, into perturbations its list does not
// hold. So a candidate whose object-frame origin is farther than the
// object's rebaseDistance (at most 64 object units and 64 of its sizes) is
// searched in f64 terms: its object ray is formed in f64 from the world ray
// through the object's f64 transform, and re-based to the point of the ray
// nearest the cell's centre, tref; the search then runs in s = t - tref,
// whose f32 steps are those of the cell's size, and t = tref + s is
// returned in f64 (docs/stability.md, "Far views").
// ---------------------------------------------------------------------------

// FAR_RAYS (spec_constants.glsl) is 0 when no ray of the scene starts
// beyond any object's rebaseDistance (GpuScene::far_rays, decided on the
// host from how far the scene, its lights and the camera's keyframes
// reach): the far-ray search and the per-candidate load of rebaseDistance
// then compile out.

// The ray in object `object`'s frame, in f64: its f64 world-to-object map
// applied to the f32 world origin and direction.
void objectRay64(uint object, vec3 worldOrigin, vec3 worldDir, out dvec3 o, out dvec3 d) {
    double m[12] = objects[object].worldToObject;
    dmat3 l = dmat3(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8]);
    o = l * dvec3(worldOrigin) + dvec3(m[9], m[10], m[11]);
    d = l * dvec3(worldDir);
}

// The first root of F' in one candidate box (cell `cellIndex` of `object`):
// (o, d) is the hardware's f32 object ray, (worldOrigin, worldDir) the world
// ray, and roots are sought for t in [tmin, tmax] (tmax64: tmax in f64, the
// closest root so far). Returns s, or NO_ROOT for none: the root is at
// t = tref + s, where `far` tells whether the ray was re-based (as above);
// a near ray has tref = 0 and is searched in f32 alone, as before far rays
// were re-based. Both backends call it (traverse.glsl, intersect.rint),
// once per candidate (one call site of cellFirstRoot: the compiler inlines
// it).
float candidateFirstRoot(uint object, uint cellIndex, vec3 o, vec3 d, vec3 worldOrigin, vec3 worldDir, float tmin,
                         float tmax, double tmax64, out bool far, out double tref, out vec3 hitPoint) {
    far = false;
    if (FAR_RAYS != 0u) {
        float rebase = objects[object].rebaseDistance;
        far = dot(o, o) > rebase * rebase;
    }
    dvec3 o64 = dvec3(0.0), d64 = dvec3(0.0);
    tref = 0.0;
    float lo = tmin, hi = tmax;
    if (far) {
        objectRay64(object, worldOrigin, worldDir, o64, d64);
        Cell cell = cells[cellIndex];
        dvec3 centre = 0.5 * (dvec3(cell.lo[0], cell.lo[1], cell.lo[2]) + dvec3(cell.hi[0], cell.hi[1], cell.hi[2]));
        tref = dot(centre - o64, d64) / dot(d64, d64);
        o64 += tref * d64;
        o = vec3(o64);
        d = vec3(d64);
        lo = float(double(tmin) - tref);
        hi = float(tmax64 - tref);
    }
    return cellFirstRoot(object, cellIndex, o, d, far, o64, d64, lo, hi, hitPoint);
}

#endif
