// Ray intersection with functional objects through ray queries.
//
// F'(p) = F(p) + Σ f_i max(Q_i(p), 0)³ (NOTES.md eq. 1-2), inside where F' >= 0.
// Each candidate AABB is a cell of one object that lists the perturbations
// that can be non-zero in it. Along the ray inside the cell, F and each Q_i
// are quadratics in t; the roots of the Q_i cut the segment into pieces on
// which F' is a polynomial of degree <= 6, whose first root is isolated
// exactly (roots.glsl). The f64 twin is src/geometry/reference.rs.
#ifndef INTERSECT_GLSL
#define INTERSECT_GLSL

#include "interface.glsl"
#include "roots.glsl"

// Specialisation constant for cost breakdowns (benchmarks): INTERSECT_FULL,
// INTERSECT_BOXES (each candidate box reports a hit where the ray enters it:
// traversal cost only) or INTERSECT_BASE (perturbations ignored: the base
// quadric's roots in each box).
layout(constant_id = 0) const uint INTERSECT_MODE = INTERSECT_FULL;

float quadricAt(Quadric q, vec3 p) {
    return q.a[0] * p.x * p.x + q.a[1] * p.y * p.y + q.a[2] * p.z * p.z
         + 2.0 * (q.a[3] * p.x * p.y + q.a[4] * p.y * p.z + q.a[5] * p.x * p.z)
         + q.b[0] * p.x + q.b[1] * p.y + q.b[2] * p.z + q.c;
}

vec3 quadricGradient(Quadric q, vec3 p) {
    return 2.0 * vec3(q.a[0] * p.x + q.a[3] * p.y + q.a[5] * p.z,
                      q.a[3] * p.x + q.a[1] * p.y + q.a[4] * p.z,
                      q.a[5] * p.x + q.a[4] * p.y + q.a[2] * p.z)
         + vec3(q.b[0], q.b[1], q.b[2]);
}

// q(p + s d) = x + y s + z s² as vec3(x, y, z).
vec3 quadricAlongRay(Quadric q, vec3 p, vec3 d) {
    vec3 ad = vec3(q.a[0] * d.x + q.a[3] * d.y + q.a[5] * d.z,
                   q.a[3] * d.x + q.a[1] * d.y + q.a[4] * d.z,
                   q.a[5] * d.x + q.a[4] * d.y + q.a[2] * d.z);
    return vec3(quadricAt(q, p), 2.0 * dot(p, ad) + dot(vec3(q.b[0], q.b[1], q.b[2]), d), dot(d, ad));
}

// Roots of x + y s + z s², without cancellation; NO_ROOT where absent.
vec2 quadraticRoots(vec3 q) {
    if (q.z == 0.0) return vec2(q.y != 0.0 ? -q.x / q.y : NO_ROOT, NO_ROOT);
    float disc = q.y * q.y - 4.0 * q.z * q.x;
    if (disc < 0.0) return vec2(NO_ROOT);
    float s = -0.5 * (q.y + (q.y >= 0.0 ? 1.0 : -1.0) * sqrt(disc));
    if (s == 0.0) return vec2(0.0);
    float r0 = s / q.z, r1 = q.x / s;
    return vec2(min(r0, r1), max(r0, r1));
}

// Adds f · q³ to c, for a quadratic q = (x, y, z).
void addCube(inout float c[7], vec3 q, float f) {
    float s0 = q.x * q.x, s1 = 2.0 * q.x * q.y, s2 = q.y * q.y + 2.0 * q.x * q.z, s3 = 2.0 * q.y * q.z, s4 = q.z * q.z;
    c[0] += f * (s0 * q.x);
    c[1] += f * (s0 * q.y + s1 * q.x);
    c[2] += f * (s0 * q.z + s1 * q.y + s2 * q.x);
    c[3] += f * (s1 * q.z + s2 * q.y + s3 * q.x);
    c[4] += f * (s2 * q.z + s3 * q.y + s4 * q.x);
    c[5] += f * (s3 * q.z + s4 * q.y);
    c[6] += f * (s4 * q.z);
}

// First root of x + y s + z s² in [lo, hi] (closed form), or NO_ROOT.
float quadraticFirstRoot(vec3 q, float lo, float hi) {
    vec2 r = quadraticRoots(q);
    if (r.x >= lo && r.x <= hi) return r.x;
    if (r.y >= lo && r.y <= hi) return r.y;
    return NO_ROOT;
}

// The range (min, max) of x + y s + z s² over [lo, hi].
vec2 quadraticRange(vec3 q, float lo, float hi) {
    float a = q.x + lo * (q.y + lo * q.z), b = q.x + hi * (q.y + hi * q.z);
    vec2 r = vec2(min(a, b), max(a, b));
    if (q.z != 0.0) {
        float v = -q.y / (2.0 * q.z);
        if (v > lo && v < hi) {
            float m = q.x + v * (q.y + v * q.z);
            r = vec2(min(r.x, m), max(r.y, m));
        }
    }
    return r;
}

// True when x + y s + z s² > 0 somewhere in [lo, hi].
bool positiveSomewhere(vec3 q, float lo, float hi) {
    if (q.x + lo * (q.y + lo * q.z) > 0.0 || q.x + hi * (q.y + hi * q.z) > 0.0) return true;
    if (q.z >= 0.0) return false;
    float v = -q.y / (2.0 * q.z);
    return v > lo && v < hi && q.x + v * (q.y + v * q.z) > 0.0;
}

// True when perturbation k is non-zero somewhere on p + s d, s in [lo, hi]:
// first a cheap test against its bounding sphere, then its quadric, whose
// restriction to the ray it returns in `q`.
bool perturbationOnSegment(uint k, vec3 p, vec3 d, float lo, float hi, out vec3 q) {
    vec3 h = p - v3(perturbations[k].centre);
    float radius = perturbations[k].radius;
    q = vec3(0.0);
    if (radius >= 0.0) {
        float dd = dot(d, d), b = dot(h, d);
        float disc = b * b - dd * (dot(h, h) - radius * radius);
        if (disc < 0.0) return false;
        float sq = sqrt(disc);
        if ((-b + sq) < lo * dd || (-b - sq) > hi * dd) return false;
    }
    q = quadricAlongRay(perturbations[k].q, h, d);
    return positiveSomewhere(q, lo, hi);
}

// Perturbations of one cell that are positive somewhere on the ray segment;
// only they cut the segment into pieces and add terms to F'. Their
// restrictions to the ray are kept in registers.
const uint MAX_RELEVANT = 8u;

// q(s) re-expanded around s = m: q(m + u) as a quadratic in u.
vec3 shiftQuadratic(vec3 q, float m) {
    return vec3(q.x + m * (q.y + m * q.z), q.y + 2.0 * m * q.z, q.z);
}

// Restriction of perturbation k to p + s d.
vec3 perturbationAlongRay(uint k, vec3 p, vec3 d) {
    return quadricAlongRay(perturbations[k].q, p - v3(perturbations[k].centre), d);
}

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
    [[dont_unroll]] for (uint i = 0; i < cell.count; ++i) {
        uint k = cellLists[cell.first + i];
        double q = quadricAt64(perturbations[k].q, p - dvec3(v3(perturbations[k].centre)));
        if (q > 0.0) v += double(perturbations[k].f) * q * q * q;
    }
    return v;
}

// A root of F' along O + t D in [a, b], where fa = F'(a) and fb = F'(b)
// have opposite signs: regula falsi with the Illinois modification.
double bracketedRoot64(uint object, Cell cell, dvec3 O, dvec3 D, double a, double b, double fa, double fb) {
    int side = 0;
    double c = a;
    [[dont_unroll]] for (int it = 0; it < 60; ++it) {
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
    for (int j = 0; j < 7; ++j) {
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
// parameter, or -1 for none.
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
        for (int j = 0; j < 7; ++j) {
            size += abs(c[j]) * xp;
            xp *= abs(tr);
        }
        if (!startUncertain && 16.0 * 5.96e-8 * size <= 1e-5 * float(tb - ta) * abs(slope)) return t;
    } else if (!startUncertain && !signUncertain(c, float(tb - tm))) {
        return -1.0;
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
    [[dont_unroll]] for (int i = 0; i < 5; ++i) v[i] = cellValue64(object, cell, O + at[i] * D);
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
    [[dont_unroll]] for (int i = 0; i < 4 && lo < 0; ++i) {
        if ((v[i] < 0.0) != (v[i + 1] < 0.0)) lo = i;
    }
    if (lo < 0) return -1.0;
    if (found && !flatRoot && at[lo] <= t && t <= at[lo + 1] && at[lo + 1] - at[lo] <= 2.0 * w) return t;
    if (v[lo] == 0.0) return at[lo];
    return bracketedRoot64(object, cell, O, D, at[lo], at[lo + 1], v[lo], v[lo + 1]);
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
    vec3 inv = 1.0 / d;
    vec3 ta = (vec3(cell.lo[0], cell.lo[1], cell.lo[2]) - o) * inv;
    vec3 tb = (vec3(cell.hi[0], cell.hi[1], cell.hi[2]) - o) * inv;
    vec3 tmn = min(ta, tb), tmx = max(ta, tb);
    float t0 = max(max(max(tmn.x, tmn.y), tmn.z), tlo);
    float t1 = min(min(min(tmx.x, tmx.y), tmx.z), thi);
    if (!(t0 <= t1)) return NO_ROOT;

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

    // Gather the relevant perturbations. With more than MAX_RELEVANT of them
    // the segment is split in halves, each gathered again; where even a short
    // segment has more (many overlapping perturbations), the cell's whole list
    // is used, read from memory (slower, still exact).
    float segLo = s0;
    for (int split = 0; split < 64 && segLo < s1; ++split) {
        float segHi = s1;
        vec3 relQ[MAX_RELEVANT];
        float relF[MAX_RELEVANT];
        uint nrel = 0u;
        bool overflow = false;
        for (int attempt = 0; attempt < 8; ++attempt) {
            nrel = 0u;
            overflow = false;
            for (uint i = 0; i < cell.count; ++i) {
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
        for (uint piece = 0; piece <= 2u * nrel && sa < segHi; ++piece) {
            float sb = segHi;
            for (uint i = 0; i < nrel; ++i) {
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
            for (uint i = 0; i < nrel; ++i) {
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
                if (t64 >= 0.0) {
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

// ∇F' at p (object frame), with the perturbations listed by the cell.
vec3 cellGradient(uint object, uint cellIndex, vec3 p) {
    Cell cell = cells[cellIndex];
    vec3 g = quadricGradient(objects[object].base, p);
    for (uint i = 0; i < cell.count; ++i) {
        uint k = cellLists[cell.first + i];
        vec3 h = p - v3(perturbations[k].centre);
        float radius = perturbations[k].radius;
        if (radius >= 0.0 && dot(h, h) > radius * radius) continue;
        float q = quadricAt(perturbations[k].q, h);
        if (q > 0.0) g += 3.0 * perturbations[k].f * q * q * quadricGradient(perturbations[k].q, h);
    }
    return g;
}

// Hessian of F' at p (object frame): H_F + Σ 3 f q (2 ∇q ∇qᵀ + q H_q) over
// the cell's perturbations with q > 0. Twin: FunctionalObject::hessian.
mat3 quadricHessian(Quadric q) {
    return 2.0 * mat3(q.a[0], q.a[3], q.a[5], q.a[3], q.a[1], q.a[4], q.a[5], q.a[4], q.a[2]);
}

mat3 cellHessian(uint object, uint cellIndex, vec3 p) {
    Cell cell = cells[cellIndex];
    mat3 hess = quadricHessian(objects[object].base);
    for (uint i = 0; i < cell.count; ++i) {
        uint k = cellLists[cell.first + i];
        vec3 h = p - v3(perturbations[k].centre);
        float radius = perturbations[k].radius;
        if (radius >= 0.0 && dot(h, h) > radius * radius) continue;
        Quadric pq = perturbations[k].q;
        float q = quadricAt(pq, h);
        if (q > 0.0) {
            vec3 g = quadricGradient(pq, h);
            hess += (3.0 * perturbations[k].f * q) * (2.0 * outerProduct(g, g) + q * quadricHessian(pq));
        }
    }
    return hess;
}

struct SceneHit {
    float t;             // NO_ROOT on a miss
    uint object;
    uint cell;           // index into cells[] of the hit's cell
    vec3 normal;         // world space, outward (-∇F'), unit length
    float gradientLength;  // |∇F'| in world units (0 on a miss)
    vec3 objectPoint;    // the hit in the object's frame
    mat3 worldToObject;  // linear part of the world-to-object transform
    float offset;        // how far secondary rays start off the surface (world units)
};

// How far along the normal a secondary ray must start from a hit at `p`
// (world, camera-relative) to stay off its own surface: more than the hit
// point's error along the normal, which has two parts (docs/stability.md,
// "Secondary-ray offsets"):
// - the f32 world position: a few ulps of its largest coordinate
//   (OFFSET_WORLD = 1e-6 is about 8 ulps);
// - the root found in the object frame: a small fraction of the cell's
//   width along the normal, since the root's error along the ray is a
//   fraction of the chord through the cell, whose component along the
//   normal is at most that width (OFFSET_CELL = 1e-4).
// A fixed 2e-4 · max(|p|, 1) before lost contact shadows of objects smaller
// than ~1e-3 of their distance, or of objects smaller than 1e-3 units.
const float OFFSET_WORLD = 1e-6;
const float OFFSET_CELL = 1e-4;

float hitOffset(vec3 p, uint cellIndex, vec3 objectNormal, mat3 worldToObject) {
    Cell cell = cells[cellIndex];
    vec3 extent = vec3(cell.hi[0], cell.hi[1], cell.hi[2]) - vec3(cell.lo[0], cell.lo[1], cell.lo[2]);
    // The cell's width along the normal in the object frame (its diagonal
    // where the gradient vanishes), in world units through the
    // object-to-world map's largest stretch (an upper bound).
    float g = length(objectNormal);
    float width = g > 0.0 ? dot(abs(objectNormal / g), extent) : length(extent);
    mat3 objectToWorld = inverse(worldToObject);
    float stretch = max(max(length(objectToWorld[0]), length(objectToWorld[1])), length(objectToWorld[2]));
    float far = max(max(abs(p.x), abs(p.y)), abs(p.z));
    return OFFSET_WORLD * far + OFFSET_CELL * width * stretch;
}

// Offset along the geometric normal by `offset` (`SceneHit::offset`), to the
// side of `dir`.
vec3 offsetOrigin(vec3 p, vec3 n, vec3 dir, float offset) {
    return p + (dot(dir, n) >= 0.0 ? n : -n) * offset;
}

// The object (instance custom index) and its cell (index into cells[]) of
// the candidate or committed intersection; `committed` must be a literal.
#define candidateObject(rq, committed) uint(rayQueryGetIntersectionInstanceCustomIndexEXT(rq, committed))
#define candidateCell(rq, object, committed) \
    (objects[object].firstCell + uint(rayQueryGetIntersectionPrimitiveIndexEXT(rq, committed)))

// Object-frame distance of a ray's origin beyond which the object ray is
// formed in f64.
const float REBASE_DISTANCE = 64.0;

// The ray in the candidate's object frame, in f64: the world-to-object
// transform applied in f64 to the f32 world origin and direction (the
// hardware's f32 transform loses ~1e-7 of the origin's distance, 1e-3 at
// 1e4, and turns the direction by ~1e-7 rad, as much again 1e4 away).
void candidateObjectRay64(rayQueryEXT rq, out dvec3 o, out dvec3 d) {
    mat4x3 m = rayQueryGetIntersectionWorldToObjectEXT(rq, false);
    dmat3 l = dmat3(dvec3(m[0]), dvec3(m[1]), dvec3(m[2]));
    o = l * dvec3(rayQueryGetWorldRayOriginEXT(rq)) + dvec3(m[3]);
    d = l * dvec3(rayQueryGetWorldRayDirectionEXT(rq));
}

// Runs the candidate loop: for each AABB, the first root in the cell.
// Returns the object-space point of the closest root found.
vec3 proceedFunctional(rayQueryEXT rq, float tmin, float tmax) {
    float best = tmax;
    vec3 bestPoint = vec3(0.0);
    // Rays from far away (object-frame origin beyond REBASE_DISTANCE) form
    // their object ray in f64; nearer rays use the hardware's f32 object
    // ray, whose error (~1e-7 of the distance) is then below 1e-5. Cost
    // measured on lavapipe (`make bench`, one run each, alternated): 0 – 10 %
    // more time for near rays (the f64 path present in the shader).
    while (rayQueryProceedEXT(rq)) {
        if (rayQueryGetIntersectionTypeEXT(rq, false) != gl_RayQueryCandidateIntersectionAABBEXT) continue;
        uint object = candidateObject(rq, false);
        vec3 o = rayQueryGetIntersectionObjectRayOriginEXT(rq, false);
        vec3 d = rayQueryGetIntersectionObjectRayDirectionEXT(rq, false);
        bool rebased = dot(o, o) > REBASE_DISTANCE * REBASE_DISTANCE;
        dvec3 o64 = dvec3(0.0), d64 = dvec3(0.0);
        if (rebased) {
            candidateObjectRay64(rq, o64, d64);
            o = vec3(o64);
            d = vec3(d64);
        }
        vec3 point;
        float t = cellFirstRoot(object, candidateCell(rq, object, false), o, d, rebased, o64, d64, tmin, best, point);
        if (t != NO_ROOT && t <= best) {
            best = t;
            bestPoint = point;
            rayQueryGenerateIntersectionEXT(rq, t);
        }
    }
    return bestPoint;
}

// The closest hit of o + t d, t in [tmin, tmax] (world space); with
// `anyHit`, any hit, with only its t and object (a shadow ray).
SceneHit traceSceneWith(vec3 o, vec3 d, float tmin, float tmax, bool anyHit) {
    rayQueryEXT rq;
    uint flags = anyHit ? gl_RayFlagsTerminateOnFirstHitEXT : gl_RayFlagsNoneEXT;
    rayQueryInitializeEXT(rq, tlas, flags, 0xFF, o, tmin, d, tmax);
    vec3 point = proceedFunctional(rq, tmin, tmax);
    SceneHit h;
    h.t = NO_ROOT;
    h.object = NO_HIT;
    h.cell = 0u;
    h.normal = vec3(0.0);
    h.gradientLength = 0.0;
    h.objectPoint = vec3(0.0);
    h.worldToObject = mat3(1.0);
    h.offset = 0.0;
    if (rayQueryGetIntersectionTypeEXT(rq, true) == gl_RayQueryCommittedIntersectionGeneratedEXT) {
        h.t = rayQueryGetIntersectionTEXT(rq, true);
        h.object = candidateObject(rq, true);
        if (anyHit) return h;
        uint cell = candidateCell(rq, h.object, true);
        h.cell = cell;
        h.objectPoint = point;
        vec3 g = cellGradient(h.object, cell, h.objectPoint);
        h.worldToObject = mat3(rayQueryGetIntersectionWorldToObjectEXT(rq, true));
        vec3 n = -(transpose(h.worldToObject) * g);
        float len = length(n);
        h.normal = len > 0.0 ? n / len : -d;
        h.gradientLength = len;
        h.offset = hitOffset(o + h.t * d, cell, g, h.worldToObject);
    }
    return h;
}

// The closest hit of o + t d, t in [tmin, tmax] (world space).
SceneHit traceScene(vec3 o, vec3 d, float tmin, float tmax) { return traceSceneWith(o, d, tmin, tmax, false); }

// The shape operator of the surface at a hit (the derivative of the outward
// unit normal along the surface, positive on a convex bump) in the tangent
// basis (t1, t2), world units: S_ij = -t_iᵀ Mᵀ H M t_j / |Mᵀ ∇F'| with M the
// world-to-object map (F'(M p + c) in world space). Exact: the analytic
// Hessian of F'. Twin: FunctionalObject::curvatures.
mat2 shapeOperator(SceneHit h, vec3 t1, vec3 t2) {
    float len = h.gradientLength;
    if (len == 0.0) return mat2(0.0);
    mat3 hess = cellHessian(h.object, h.cell, h.objectPoint);
    vec3 a = h.worldToObject * t1, b = h.worldToObject * t2;
    float s11 = -dot(a, hess * a) / len, s12 = -dot(a, hess * b) / len, s22 = -dot(b, hess * b) / len;
    return mat2(s11, s12, s12, s22);
}

// True when something blocks o + t d for t in [tmin, tmax].
bool occluded(vec3 o, vec3 d, float tmin, float tmax) {
    rayQueryEXT rq;
    rayQueryInitializeEXT(rq, tlas, gl_RayFlagsTerminateOnFirstHitEXT, 0xFF, o, tmin, d, tmax);
    proceedFunctional(rq, tmin, tmax);
    return rayQueryGetIntersectionTypeEXT(rq, true) != gl_RayQueryCommittedIntersectionNoneEXT;
}

#endif
