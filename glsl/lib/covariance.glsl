// Covariance footprints along light paths (after Belcour et al., "5D
// Covariance Tracing for Efficient Defocus and Motion Blur", TOG 2013, and
// "Antialiasing Complex Global Illumination Effects in Path-space", TOG
// 2017), kept in the primal domain: P is the 4x4 covariance of the ray
// bundle's offsets (x, y, θ, φ) in a frame (e1, e2) across the ray. Linear
// operators A act as P' = A P Aᵀ (the spectral form of src/model/covariance.rs:
// Σ⁻¹ = 4π² P). Lobes are sampled by the path, so their bandwidth is never
// added to the footprint (that would filter twice). First order throughout; the surface's
// exact curvature (shape operator from the analytic Hessian of F') shears
// the outgoing angles by the tilt of the normal across the footprint.
//
// Clamps (each keeps the matrix finite; none is active on ordinary paths):
// - every entry is clamped to ±COV_MAX (1e12) after each operator, NaN -> 0;
// - 1 / |cos θ| on a surface is bounded by 1 / MIN_FOOTPRINT_COS = 1000
//   (grazing hits: texfilter.glsl), and cos θt in a refraction's angle
//   scale by 0.05 (the scale is at most 20η).
#ifndef COVARIANCE_GLSL
#define COVARIANCE_GLSL

#include "common.glsl"
#include "texfilter.glsl"

struct PathCovariance {
    // The primal covariance of (x, y, θ, φ) in 2 x 2 blocks (every operator
    // below is block-structured, so the 4 x 4 products are never formed):
    // P = [xx xa; xaᵀ aa], xa the covariance of the spatial offsets (rows)
    // with the angular ones (columns); GLSL's column-major mat2 throughout.
    mat2 xx;
    mat2 xa;
    mat2 aa;
    vec3 e1;   // frame across the ray
    vec3 e2;
};

// The kinds of bounce of bounceJacobian.
const uint TURN_REFLECT = 0u;
const uint TURN_DIFFUSE = 1u;
const uint TURN_REFRACT = 2u;

// Largest variance kept (keeps the matrix finite; about a 1e6 std).
const float COV_MAX = 1e12;

mat2 covClamp2(mat2 m) {
    for (int c = 0; c < 2; ++c)
        for (int r = 0; r < 2; ++r) {
            float v = m[c][r];
            m[c][r] = (isnan(v) || isinf(v)) ? 0.0 : clamp(v, -COV_MAX, COV_MAX);
        }
    return m;
}

void covClamp(inout PathCovariance c) {
    c.xx = covClamp2(c.xx);
    c.xa = covClamp2(c.xa);
    c.aa = covClamp2(c.aa);
}

// At the camera: the footprint's share of the pixel filter, a Gaussian of
// angular standard deviation `sigma` (camera.glsl, footprintSigma), no
// spatial extent (a pinhole).
PathCovariance covCamera(vec3 d, vec3 up, float sigma) {
    PathCovariance c;
    c.e1 = normalize(cross(d, up));
    c.e2 = cross(c.e1, d);
    float v = sigma * sigma;
    c.xx = mat2(0.0);
    c.xa = mat2(0.0);
    c.aa = mat2(v);
    return c;
}

// Free travel over distance t: x += t θ, y += t φ.
void covTravel(inout PathCovariance c, float t) {
    c.xx += t * (c.xa + transpose(c.xa)) + (t * t) * c.aa;
    c.xa += t * c.aa;
    covClamp(c);
}

// Re-expresses the spatial and angular offsets in a new frame (e1n, e2n)
// across the same ray.
void covRotate(inout PathCovariance c, vec3 e1n, vec3 e2n) {
    mat2 m = mat2(dot(c.e1, e1n), dot(c.e1, e2n), dot(c.e2, e1n), dot(c.e2, e2n));
    mat2 mt = transpose(m);
    // The same rotation of the spatial and the angular offsets.
    c.xx = m * c.xx * mt;
    c.xa = m * c.xa * mt;
    c.aa = m * c.aa * mt;
    covClamp(c);
    c.e1 = e1n;
    c.e2 = e2n;
}

// The tangent basis of a hit for footprints: t1 along the ray's projection
// on the surface, t2 = n × t1.
void footprintBasis(vec3 d, vec3 n, out vec3 t1, out vec3 t2) {
    vec3 along = d - n * dot(n, d);
    float al = length(along);
    t1 = al > 1e-6 ? along / al : frameAround(n)[0];
    t2 = cross(n, t1);
}

// Meets a surface of normal n, with the basis (t1, t2) of footprintBasis:
// turns the path's frame so that e1 is the component of t1 across the ray
// and e2 = t2, and returns the spatial covariance on the surface in the
// tangent basis (t1, t2): an offset x along e1 covers x / |cos θ| along t1
// (bounded: MIN_FOOTPRINT_COS). `inv` returns that 1 / |cos θ|.
mat2 covOnSurface(inout PathCovariance c, vec3 d, vec3 n, vec3 t1, vec3 t2, out float inv) {
    vec3 e1n = t1 - d * dot(d, t1);
    float el = length(e1n);
    e1n = el > 1e-6 ? e1n / el : normalize(cross(t2, d));
    covRotate(c, e1n, t2);
    inv = 1.0 / max(abs(dot(d, n)), MIN_FOOTPRINT_COS);
    return mat2(c.xx[0][0] * inv * inv, c.xx[0][1] * inv, c.xx[1][0] * inv, c.xx[1][1]);
}

// The frame across an outgoing ray wi chosen as in covOnSurface: e1 from
// t1, e2 across wi and e1 on t2's side (orthonormal also where wi leaves
// the plane of incidence, as a glossy sample does).
void outgoingFrame(vec3 t1, vec3 t2, vec3 wi, out vec3 e1n, out vec3 e2n) {
    e1n = t1 - wi * dot(wi, t1);
    float el = length(e1n);
    e1n = el > 1e-6 ? e1n / el : normalize(cross(t2, wi));
    e2n = cross(wi, e1n);
    if (dot(e2n, t2) < 0.0) e2n = -e2n;
}

// Leaves the surface along wi. With the frames chosen as in covOnSurface
// (e1 from t1, e2 from t2, on both sides) a flat mirror is the identity (the
// unfolded path); the spatial offsets are the surface offsets seen across
// the outgoing ray (e1n, e2n: outgoingFrame's). The outgoing angles:
// θ' = A θ + T (S u) (A and T from bounceJacobian, in that frame):
// - A: how the outgoing direction turns per unit turn of the incoming one
//   along the incoming frame's e1, e2;
// - curvature (Belcour et al. 2013, sec. 4, "curvature", here in primal
//   form): at surface offset u = (x / |cos θ|, y) the normal facing the
//   incoming ray tilts by S u (S: shape operator of that normal in
//   (t1, t2)), which turns the outgoing direction by T (S u).
// The lobe itself is sampled (the path's direction), so its bandwidth is
// not added here.
void covBounce(inout PathCovariance c, float inv, vec3 t1, vec3 t2, vec3 e1n, vec3 e2n, mat2 shape, mat2 turn,
               mat2 dg) {
    // Incoming (x, y) -> surface (x / |cos θ|, y) -> outgoing across wi.
    mat2 toSurface = mat2(inv, 0.0, 0.0, 1.0);
    mat2 m = mat2(dot(t1, e1n), dot(t1, e2n), dot(t2, e1n), dot(t2, e2n)) * toSurface;
    mat2 shear = turn * shape * toSurface;
    // The operator [m 0; shear A] in blocks: x' = m x, θ' = shear x + A θ.
    mat2 dgT = transpose(dg);
    mat2 xxS = c.xx * transpose(shear);
    mat2 xaD = c.xa * dgT;
    mat2 sx = shear * xaD;
    mat2 aa = shear * xxS + sx + transpose(sx) + dg * c.aa * dgT;
    c.xa = m * (xxS + xaD);
    c.xx = m * c.xx * transpose(m);
    c.aa = aa;
    covClamp(c);
    c.e1 = e1n;
    c.e2 = e2n;
}

// How a sampled direction `next` changes around the path (covBounce's A
// and T), for "the same lobe sample" on the rays around it: the sample is
// fixed in the surface's frame, which turns with the normal (a tilt of the
// facing normal nf along t is the rotation ω = nf × t).
// - A reflection keeps its microfacet normal m = (next − d) / |next − d|:
//   next = d − 2 (d·m) m. A turn of d moves next by its mirror image about
//   m (ang); a tilt turns m by ω × m and next by −2 ((d·δm) m + (d·m) δm)
//   (turn). About m = nf this is the identity for A and gains of 2 in the
//   plane of incidence and 2 cos θ across it.
// - A diffuse sample turns with the frame (ω × next); A is the identity, as
//   for a mirror (the incoming spread carried on).
// - Refraction: first order in the plane of incidence, then across it
//   (Belcour et al. 2013, appendix): angles scale by `scale`
//   (η cos θi / cos θt, η) and a tilt turns next by `gain`
//   (η cos θi / cos θt − 1, η cos θi − cos θt), along e1n, e2n.
// e1, e2: the incoming frame (covOnSurface's); e1n, e2n: the outgoing one
// (outgoingFrame's), in which A (`ang`) and T (`turn`) are returned.
void bounceJacobian(vec3 d, vec3 e1, vec3 e2, vec3 nf, vec3 next, vec3 t1, vec3 t2, vec3 e1n, vec3 e2n, uint lobe,
                    vec2 scale, vec2 gain, out mat2 turn, out mat2 ang) {
    if (lobe == TURN_REFRACT) {
        turn = mat2(gain.x, 0.0, 0.0, gain.y);
        ang = mat2(scale.x, 0.0, 0.0, scale.y);
        return;
    }
    vec3 turn1, turn2, ang1 = e1n, ang2 = e2n;
    if (lobe == TURN_DIFFUSE) {
        turn1 = t1 * dot(nf, next) - nf * dot(t1, next);
        turn2 = t2 * dot(nf, next) - nf * dot(t2, next);
    } else {
        vec3 h = next - d;
        float hl = length(h);
        vec3 m = hl > 1e-6 ? h / hl : nf;
        vec3 dm1 = t1 * dot(nf, m) - nf * dot(t1, m);
        vec3 dm2 = t2 * dot(nf, m) - nf * dot(t2, m);
        turn1 = -2.0 * (dot(d, dm1) * m + dot(d, m) * dm1);
        turn2 = -2.0 * (dot(d, dm2) * m + dot(d, m) * dm2);
        ang1 = e1 - 2.0 * dot(e1, m) * m;
        ang2 = e2 - 2.0 * dot(e2, m) * m;
    }
    // The world vectors (columns) taken across the outgoing ray.
    turn = mat2(dot(turn1, e1n), dot(turn1, e2n), dot(turn2, e1n), dot(turn2, e2n));
    ang = mat2(dot(ang1, e1n), dot(ang1, e2n), dot(ang2, e1n), dot(ang2, e2n));
}

// A scattering event in a medium, into direction wi: the bundle's spatial
// offsets are kept, projected across wi (first order); the phase lobe is
// sampled, so its spread is not added.
void covScatter(inout PathCovariance c, vec3 wi) {
    vec3 e1n = c.e1 - wi * dot(wi, c.e1);
    float l = length(e1n);
    e1n = l > 1e-6 ? e1n / l : frameAround(wi)[0];
    covRotate(c, e1n, cross(wi, e1n));
}

#endif
