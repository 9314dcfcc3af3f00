// Covariance footprints along light paths (after Belcour et al., "5D
// Covariance Tracing for Efficient Defocus and Motion Blur", TOG 2013, and
// "Antialiasing Complex Global Illumination Effects in Path-space", TOG
// 2017), kept in the primal domain: P is the 4x4 covariance of the ray
// bundle's offsets (x, y, θ, φ) in a frame (e1, e2) across the ray. Linear
// operators A act as P' = A P Aᵀ (the spectral form of src/covariance.rs:
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

struct PathCovariance {
    mat4 p;    // primal covariance of (x, y, θ, φ); columns, GLSL convention
    vec3 e1;   // frame across the ray
    vec3 e2;
};

// Largest variance kept (keeps the matrix finite; about a 1e6 std).
const float COV_MAX = 1e12;

mat4 covClamp(mat4 m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            float v = m[c][r];
            m[c][r] = (isnan(v) || isinf(v)) ? 0.0 : clamp(v, -COV_MAX, COV_MAX);
        }
    return m;
}

// At the camera: the footprint's share of the pixel filter, a Gaussian of
// angular standard deviation `sigma` (render.comp, footprintSigma), no
// spatial extent (a pinhole).
PathCovariance covCamera(vec3 d, vec3 up, float sigma) {
    PathCovariance c;
    c.e1 = normalize(cross(d, up));
    c.e2 = cross(c.e1, d);
    float v = sigma * sigma;
    c.p = mat4(0.0);
    c.p[2][2] = v;
    c.p[3][3] = v;
    return c;
}

// Free travel over distance t: x += t θ, y += t φ.
void covTravel(inout PathCovariance c, float t) {
    mat4 a = mat4(1.0);
    a[2][0] = t;  // column θ, row x
    a[3][1] = t;
    c.p = covClamp(a * c.p * transpose(a));
}

// Re-expresses the spatial and angular offsets in a new frame (e1n, e2n)
// across the same ray.
void covRotate(inout PathCovariance c, vec3 e1n, vec3 e2n) {
    mat2 m = mat2(dot(c.e1, e1n), dot(c.e1, e2n), dot(c.e2, e1n), dot(c.e2, e2n));
    mat4 a = mat4(0.0);
    a[0][0] = m[0][0]; a[0][1] = m[0][1]; a[1][0] = m[1][0]; a[1][1] = m[1][1];
    a[2][2] = m[0][0]; a[2][3] = m[0][1]; a[3][2] = m[1][0]; a[3][3] = m[1][1];
    c.p = covClamp(a * c.p * transpose(a));
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
    return mat2(c.p[0][0] * inv * inv, c.p[0][1] * inv, c.p[1][0] * inv, c.p[1][1]);
}

// Leaves the surface along wi. With the frames chosen as in covOnSurface
// (e1 from t1, e2 from t2, on both sides) a flat mirror is the identity (the
// unfolded path); the spatial offsets are the surface offsets seen across
// the outgoing ray; a refraction scales the angles by (η cos θi / cos θt, η)
// (first order).
//
// Curvature (Belcour et al. 2013, sec. 4, "curvature", here in primal form):
// at surface offset u = (x / |cos θ|, y) the normal facing the incoming ray
// tilts by S u (S: shape operator of that normal in (t1, t2)), which turns
// the outgoing direction by g ⊙ (S u). The gains g, from differentiating the
// reflection and refraction laws (in the plane of incidence, then across it):
// mirror reflection (2, 2 cos θi); refraction (η cos θi / cos θt − 1,
// η cos θi − cos θt); a diffuse lobe turns with the normal (1, 1). The
// operator is the shear θ' = s ⊙ θ + g ⊙ (S u). The lobe itself is sampled
// (the path's direction wi), so its bandwidth is not added here.
void covBounce(inout PathCovariance c, float inv, vec3 t1, vec3 t2, vec3 wi, vec2 angleScale, mat2 shape, vec2 gain) {
    vec3 e1n = t1 - wi * dot(wi, t1);
    float el = length(e1n);
    e1n = el > 1e-6 ? e1n / el : normalize(cross(t2, wi));
    vec3 e2n = t2 - wi * dot(wi, t2);
    float e2l = length(e2n);
    e2n = e2l > 1e-6 ? e2n / e2l : normalize(cross(wi, e1n));
    // Incoming (x, y) -> surface (x / |cos θ|, y) -> outgoing across wi.
    mat2 toSurface = mat2(inv, 0.0, 0.0, 1.0);
    mat2 m = mat2(dot(t1, e1n), dot(t1, e2n), dot(t2, e1n), dot(t2, e2n)) * toSurface;
    mat2 shear = mat2(gain.x, 0.0, 0.0, gain.y) * shape * toSurface;
    mat4 a = mat4(0.0);
    a[0][0] = m[0][0]; a[0][1] = m[0][1]; a[1][0] = m[1][0]; a[1][1] = m[1][1];
    a[0][2] = shear[0][0]; a[0][3] = shear[0][1]; a[1][2] = shear[1][0]; a[1][3] = shear[1][1];
    a[2][2] = angleScale.x;
    a[3][3] = angleScale.y;
    c.p = covClamp(a * c.p * transpose(a));
    c.e1 = e1n;
    c.e2 = e2n;
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
