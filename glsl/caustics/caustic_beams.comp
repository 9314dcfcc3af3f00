#version 460
// Volumetric caustics (paper section 3): the caustic rays' last segments,
// from their last specular vertex to where they land, run through the fog
// and scatter light toward the camera. Four grid rays BEAM_STRIDE apart that
// followed the same surfaces bound a beam: a frustum whose cross-section
// grows or shrinks from its start quad to its landing quad (the warped
// volumes of Ernst, Akenine-Möller & Jensen 2005). Its flux is what its
// grid cells carry; inside it, the irradiance is flux / cross-section.
//
// One invocation per beam: for every pixel its screen bounds cover, the
// camera ray through the pixel centre (up to the G-buffer receiver) passes
// the beam's axis at its closest point; when that is inside the beam (a
// round tube of the same cross-section), the light scattered toward the
// camera along the chord is σ_s p(θ) E T_camera × chord length (a beam ×
// ray estimate with the beam's own width as the kernel; compare Jarosz et
// al. 2011, "A Comprehensive Theory of Volumetric Radiance Estimation Using
// Photon Points and Beams"). The sum goes to the beam map (radiance, fixed
// point) that the render pass adds on the camera ray's first segment.
#extension GL_EXT_shader_atomic_int64 : require
// This pass traces no rays.
#define NO_TRACING
#include "interface.glsl"
#include "frame.glsl"
#include "caustics.glsl"
#include "balance.glsl"

layout(local_size_x = CAUSTIC_GROUP) in;

layout(set = 0, binding = BINDING_CAUSTIC_RAYS, scalar) buffer CausticRays { CausticRay causticRays[]; };
layout(set = 0, binding = BINDING_GBUFFER, scalar) buffer Receivers { Receiver receivers[]; };
// Per pixel: radiance × CAUSTIC_FIXED_POINT in R, G, B.
layout(set = 0, binding = BINDING_CAUSTIC_BEAMS, scalar) buffer BeamMap { uint64_t beamMap[]; };

layout(push_constant, scalar) uniform PushBlock { CausticPush pc; };

CausticRay rayAt(ivec2 g) { return causticRays[pc.emitter.firstRay + uint(g.y) * pc.emitter.grid.x + uint(g.x)]; }

// Area of the quad (a, b, c, d) seen along the unit axis u.
float crossSection(vec3 a, vec3 b, vec3 c, vec3 d, vec3 u) {
    return 0.5 * (abs(dot(cross(b - a, c - a), u)) + abs(dot(cross(c - a, d - a), u)));
}

void main() {
    uvec2 grid = pc.emitter.grid;
    int stride = int(BEAM_STRIDE);
    uvec2 beams = (grid - 1u) / uint(stride);
    uint i = balancedIndex(CAUSTIC_GROUP);
    if (i >= beams.x * beams.y) return;
    ivec2 c = ivec2(i % beams.x, i / beams.x) * stride;
    ivec2 corner[4] = ivec2[4](c, c + ivec2(stride, 0), c + ivec2(stride, stride), c + ivec2(0, stride));
    CausticRay r[4];
    for (int k = 0; k < 4; ++k) r[k] = rayAt(corner[k]);
    uint path = r[0].path;
    for (int k = 0; k < 4; ++k) {
        if (r[k].path == 0u || r[k].path != path || r[k].inFog == 0u) return;
    }
    vec3 s0 = vec3(0.0), s1 = vec3(0.0);
    vec3 flux = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        s0 += 0.25 * v3(r[k].beamStart);
        s1 += 0.25 * v3(r[k].position);
        // Each ray stands for one grid cell; the beam holds stride² of them.
        flux += 0.25 * float(stride * stride) * v3(r[k].flux);
    }
    vec3 axis = s1 - s0;
    float len = length(axis);
    if (!(len > 0.0)) return;
    vec3 u = axis / len;
    float rootA0 = sqrt(crossSection(v3(r[0].beamStart), v3(r[1].beamStart), v3(r[2].beamStart), v3(r[3].beamStart), u));
    float rootA1 = sqrt(crossSection(v3(r[0].position), v3(r[1].position), v3(r[2].position), v3(r[3].position), u));

    Medium fog = fogMedium();
    vec3 sigmaS = fog.density * v3(fog.albedo);
    // Screen bounds of the beam's eight corners.
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    for (int k = 0; k < 8; ++k) {
        vec3 p = k < 4 ? v3(r[k].beamStart) : v3(r[k - 4].position);
        vec2 px;
        if (!project(p, px)) return;
        lo = min(lo, px);
        hi = max(hi, px);
    }
    ivec2 first = max(ivec2(floor(lo - 0.5)), ivec2(0));
    ivec2 last = min(ivec2(ceil(hi - 0.5)), ivec2(frame.width, frame.height) - 1);
    for (int y = first.y; y <= last.y; ++y) {
        for (int x = first.x; x <= last.x; ++x) {
            uint pixel = uint(y) * frame.width + uint(x);
            vec3 v = cameraRay(vec2(x, y) + 0.5);
            Receiver rc = receivers[pixel];
            float tMax = rc.object == NO_HIT ? 1e30 : length(v3(rc.position) - frame.eye);
            // Closest points of the camera ray eye + t v and the axis s0 + s u.
            vec3 w0 = frame.eye - s0;
            float b = dot(v, u), dv = dot(v, w0), du = dot(u, w0);
            float denom = 1.0 - b * b;
            if (denom < 1e-6) continue;  // looking along the beam
            float t = (b * du - dv) / denom;
            float s = (du - b * dv) / denom;
            if (t <= 0.0 || t >= tMax || s <= 0.0 || s >= len) continue;
            float delta = length(frame.eye + t * v - (s0 + s * u));
            float rootA = mix(rootA0, rootA1, s / len);
            // A beam narrower than a pixel is widened to 1.5 pixels (its
            // flux spread over the wider tube): sampled at pixel centres, a
            // thinner one would alias into isolated bright dots.
            float pixelWidth = t * 2.0 * length(frame.up) / float(frame.height);
            float rho2 = max(rootA * rootA / PI, 0.5625 * pixelWidth * pixelWidth);
            float area = PI * rho2;
            if (!(delta * delta < rho2)) continue;
            float chord = 2.0 * sqrt(rho2 - delta * delta) / sqrt(denom);
            // The flux was measured where the rays landed; upstream it had
            // not yet lost exp(−σ_t (len − s)).
            vec3 irradiance = flux * exp(fog.density * (len - s)) / area;
            float phase = hgPdf(fog.anisotropy, dot(u, -v));
            vec3 radiance = sigmaS * phase * irradiance * exp(-fog.density * t) * chord;
            if (any(isnan(radiance)) || any(isinf(radiance))) continue;
            u64vec3 fixedPoint = u64vec3(radiance * float(CAUSTIC_FIXED_POINT) + 0.5);
            atomicAdd(beamMap[3u * pixel], fixedPoint.x);
            atomicAdd(beamMap[3u * pixel + 1u], fixedPoint.y);
            atomicAdd(beamMap[3u * pixel + 2u], fixedPoint.z);
        }
    }
}
