// The footprint a path carries from the camera through every vertex, for
// the filtered texture lookups (FILTER_MODE): a ray cone (FILTER_RAY_CONES)
// or a covariance matrix (FILTER_COVARIANCE, covariance.glsl). tracePath
// keeps one PathFootprint; at each hit it builds a HitFootprint once, which
// surfaceAt's lookups and the bounce that follows share (as pbrt-v4's
// TextureEvalContext carries the footprint to the texture lookups).
//
// Ray cones: Akenine-Möller et al., "Improved Shader and Texture Level of
// Detail Using Ray Cones", JCGT 2021, kept as a Gaussian: σ of the width
// at the ray's origin and of the spread angle, starting from the footprint's
// share of the pixel filter (camera.glsl, footprintSigma). Curved surfaces turn the
// spread by their exact mean curvature. A rough or diffuse lobe does not
// widen it: the lobe is sampled, and counting its bandwidth in the
// footprint as well would filter twice.
#ifndef PATH_FOOTPRINT_GLSL
#define PATH_FOOTPRINT_GLSL

#include "render_inputs.glsl"

struct PathFootprint {
    float coneWidth;     // σ of the cone's width at the ray's origin
    float coneSpread;    // σ of its spread angle
    PathCovariance cov;  // FILTER_COVARIANCE
};

// The footprint at one hit: its covariance on the surface in the tangent
// basis (t1, t2) of footprintBasis, which every filter step shares.
struct HitFootprint {
    mat2 footprint;
    vec3 t1, t2;
    float covInv;  // covOnSurface's inverse cosine, for covBounce
    float width;   // the ray cone's width σ at the hit
    // The lookups' random choices (texfilter.glsl, Footprint.xi): a seed for
    // their numbers, or none (stochastic false: deterministic lookups).
    uint seed;
    bool stochastic;
};

// The numbers of the next lookup's random choices (texfilter.glsl,
// Footprint.xi), or -1: the deterministic lookup.
vec2 nextLookupXi(inout HitFootprint hf) { return hf.stochastic ? rand2(hf.seed) : vec2(-1.0); }

// A ray cone's footprint on the surface, in the basis (t1, t2): σ across the
// ray, σ / |cos θ| along t1 (stretch bounded: MIN_FOOTPRINT_COS).
mat2 coneFootprint(vec3 d, vec3 n, float sigma) {
    float inv = 1.0 / max(abs(dot(d, n)), MIN_FOOTPRINT_COS);
    return mat2(sigma * sigma * inv * inv, 0.0, 0.0, sigma * sigma);
}

// The footprint of a cone of width σ meeting the surface of normal n.
HitFootprint coneHitFootprint(vec3 d, vec3 n, float sigma) {
    HitFootprint f;
    footprintBasis(d, n, f.t1, f.t2);
    f.footprint = coneFootprint(d, n, sigma);
    f.covInv = 1.0;
    f.width = sigma;
    f.seed = 0u;
    f.stochastic = false;
    return f;
}

// The camera ray's footprint: a spread of σ = `angle` radians (the
// footprint's share of the pixel filter) from a point.
PathFootprint footprintAtCamera(vec3 d, float angle) {
    PathFootprint f;
    f.coneWidth = 0.0;
    f.coneSpread = angle;
    f.cov = covCamera(d, normalize(frame.up), angle);
    return f;
}

// Travels `t` along the ray to a scattering event in a medium and turns to
// `wi` there (the phase lobe is sampled, so its spread is not added).
void footprintScatter(inout PathFootprint f, float t, vec3 wi) {
    if (FILTER_MODE == FILTER_COVARIANCE) {
        covTravel(f.cov, t);
        covScatter(f.cov, wi);
    } else if (FILTER_MODE == FILTER_RAY_CONES) {
        f.coneWidth += f.coneSpread * t;
    }
}

// Travels `t` along direction d to a surface of normal n.
HitFootprint footprintAtHit(inout PathFootprint f, vec3 d, vec3 n, float t) {
    HitFootprint hf;
    hf.width = f.coneWidth + f.coneSpread * t;
    footprintBasis(d, n, hf.t1, hf.t2);
    hf.covInv = 1.0;
    hf.seed = 0u;
    hf.stochastic = false;
    if (FILTER_MODE == FILTER_COVARIANCE) {
        covTravel(f.cov, t);
        hf.footprint = covOnSurface(f.cov, d, n, hf.t1, hf.t2, hf.covInv);
    } else {
        hf.footprint = coneFootprint(d, n, hf.width);
    }
    return hf;
}

// The outgoing footprint after a BSDF sample at hit h: the normal facing
// the incoming ray d tilts by S u at surface offset u (S: its shape
// operator, exact from the Hessian of F'), which turns the outgoing
// direction `next` (covariance.glsl, bounceJacobian and covBounce; ray cones:
// by the gains g ⊙ (S u) of a mirror or a refraction);
// refraction also scales the angles. wo and wi are the local directions of
// the sample (z along the shading normal), ior the material's relative index.
void footprintBounce(inout PathFootprint f, HitFootprint hf, SceneHit h, vec3 d, vec3 next, vec3 wo, vec3 wi,
                     uint kind, float ior) {
    bool transmitted = wi.z * wo.z < 0.0;
    float cosI = abs(wo.z), cosT = max(abs(wi.z), 0.05);
    vec2 scale = vec2(1.0), gain = vec2(2.0, 2.0 * cosI);
    if (transmitted) {
        // Angles scale by η cos θi / cos θt and η, with η = n_i / n_t.
        float eta = wo.z > 0.0 ? 1.0 / ior : ior;
        scale = vec2(eta * cosI / cosT, eta);
        gain = vec2(eta * cosI / cosT - 1.0, eta * cosI - cosT);
    } else if (kind == MATERIAL_DIFFUSE) {
        gain = vec2(1.0);
    }
    float facing = dot(d, h.normal) < 0.0 ? 1.0 : -1.0;
    mat2 shape = shapeOperator(h, hf.t1, hf.t2) * facing;
    if (FILTER_MODE == FILTER_COVARIANCE) {
        uint turnKind = transmitted ? TURN_REFRACT : (kind == MATERIAL_DIFFUSE ? TURN_DIFFUSE : TURN_REFLECT);
        vec3 e1n, e2n;
        outgoingFrame(hf.t1, hf.t2, next, e1n, e2n);
        mat2 turn, ang;
        bounceJacobian(d, f.cov.e1, f.cov.e2, h.normal * facing, next, hf.t1, hf.t2, e1n, e2n, turnKind, scale, gain,
                       turn, ang);
        covBounce(f.cov, hf.covInv, hf.t1, hf.t2, e1n, e2n, shape, turn, ang);
    } else {
        // Ray cones: the curvature term of Akenine-Möller et al. 2021 (the
        // cone's edge rays turn by the gain times the mean curvature times
        // the width; a convex mirror of radius R adds 2w/R), then the angle
        // scale of a refraction.
        float kappa = 0.5 * (shape[0][0] + shape[1][1]);
        f.coneSpread = f.coneSpread * scale.x + 0.5 * (gain.x + gain.y) * kappa * hf.width;
        f.coneWidth = hf.width;
    }
}

#endif
