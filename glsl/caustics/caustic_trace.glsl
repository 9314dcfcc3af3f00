#ifndef CAUSTIC_TRACE_GLSL
#define CAUSTIC_TRACE_GLSL
// Shared by caustic_trace.comp (ray queries) and caustic_trace.rgen (pipeline backend).
// Caustic rays (paper section 3; NOTES.md section 3): one ray per point of
// an emission grid aimed at the bounds of the specular objects, traced
// through mirrors, smooth conductors and smooth dielectrics (several
// refractions: glass, then water) until it lands on a diffuse surface.
//
// Each ray follows one deterministic path so that grid neighbours stay
// comparable: transmission at a dielectric (its weight 1 − F; reflection only
// under total internal reflection), reflection at mirrors and conductors
// (weight: their reflectance); the rays of a reflecting grid
// (Emitter.reflectFirst) reflect instead at their first vertex (weight F),
// which must be glass. Media along the way attenuate it by their
// transmittance. The render pass leaves out exactly these paths from its own
// estimate (see render.glsl, "caustic paths"), so nothing is counted twice.
#include "intersect.glsl"
#include "bsdf.glsl"
#include "frame.glsl"
#include "caustics.glsl"

layout(set = 0, binding = BINDING_CAUSTIC_RAYS, scalar) buffer CausticRays { CausticRay causticRays[]; };

#include "materials.glsl"
#include "stack.glsl"

layout(push_constant, scalar) uniform PushBlock { CausticPush pc; };

// MEDIA_ENABLED: 1 when the scene has a participating medium.
#include "spec_constants.glsl"

// FNV-1a step: the path identifier of a ray so far, extended by `value`.
uint extendPath(uint path, uint value) { return (path ^ value) * 16777619u; }

void traceCausticRay(uint i) {
    Emitter e = pc.emitter;
    if (i >= e.grid.x * e.grid.y) return;
    uvec2 g = uvec2(i % e.grid.x, i / e.grid.x);
    vec2 xy = mix(e.lo, e.hi, (vec2(g) + 0.5) / vec2(e.grid));
    vec2 cell = (e.hi - e.lo) / vec2(e.grid);
    vec3 o, d;
    vec3 flux;
    if (e.kind == EMITTER_PARALLEL) {
        o = e.origin + xy.x * e.u + xy.y * e.v;
        d = e.w;
        flux = e.power * (cell.x * cell.y);
    } else {
        // Solid angle of a grid cell on the plane at distance 1: dA cos³ α.
        vec3 q = e.w + xy.x * e.u + xy.y * e.v;
        float l = length(q);
        o = e.origin;
        d = q / l;
        flux = e.power * (cell.x * cell.y / (l * l * l));
    }

    CausticRay ray;
    ray.position = float[3](0.0, 0.0, 0.0);
    ray.object = NO_HIT;
    ray.flux = float[3](0.0, 0.0, 0.0);
    ray.path = 0u;
    ray.beamStart = float[3](0.0, 0.0, 0.0);
    ray.inFog = 0u;
    MediaStack media = emptyStack();
    uint path = 2166136261u;
    uint speculars = 0u;
    for (uint step = 0u; step < 4u * e.maxSpecular + 8u; ++step) { LOOP_EDGE();
        SceneHit h = traceScene(o, d, 0.0, 1e30);
        if (h.object == NO_HIT) break;
        if (MEDIA_ENABLED != 0u) {
            Medium med = mediumOf(media);
            flux *= exp(-med.density * h.t);
        }
        vec3 p = o + h.t * d;
        uint matIndex = objects[h.object].material;
        Material mat = materials[matIndex];
        if (mat.kind == MATERIAL_DIFFUSE) {
            if (speculars > 0u) {
                ray.position = float[3](p.x, p.y, p.z);
                ray.object = h.object;
                ray.flux = float[3](flux.x, flux.y, flux.z);
                ray.path = max(extendPath(path, h.object), 1u);
                ray.beamStart = float[3](o.x, o.y, o.z);
                ray.inFog = MEDIA_ENABLED != 0u && media.count == 0u && frame.fog.density > 0.0 ? 1u : 0u;
            }
            break;
        }
        if (!isDelta(mat) || speculars == e.maxSpecular) break;
        // A ray of a reflecting grid at its first specular vertex.
        bool reflectHere = e.reflectFirst != 0u && speculars == 0u;
        bool entering = dot(d, h.normal) < 0.0;
        vec3 n = entering ? h.normal : -h.normal;  // facing the ray
        float cosI = -dot(d, n);
        vec3 reflected = d + 2.0 * cosI * n;
        uint event;
        if (mat.kind == MATERIAL_DIELECTRIC) {
            float eta = mat.ior / farSideIor(media, matIndex, entering);  // n_inside / n_outside
            if (abs(eta - 1.0) < 1e-6) {
                // Index-matched: not an interface at all.
                crossInterface(media, matIndex, entering);
                o = offsetOrigin(p, h.normal, d, h.offset);
                continue;
            }
            float etaRel = entering ? eta : 1.0 / eta;  // n_t / n_i
            float f = fresnelDielectric(cosI, etaRel);
            if (reflectHere) {
                // The reflecting grid: reflection (weight F) at the first
                // vertex, unless the glass reflects totally there (the
                // refracting grid has that path).
                if (!(f < 1.0)) break;
                d = reflected;
                flux *= f;
                event = 2u;
            } else if (f < 1.0) {
                float cosT = sqrt(max(0.0, 1.0 - (1.0 - cosI * cosI) / (etaRel * etaRel)));
                d = normalize(d / etaRel + (cosI / etaRel - cosT) * n);
                flux *= 1.0 - f;
                crossInterface(media, matIndex, entering);
                event = 1u;
            } else {
                d = reflected;
                event = 2u;
            }
        } else {
            // The reflecting grid starts at glass only (the refracting grid
            // has the paths that start at a mirror).
            if (reflectHere) break;
            d = reflected;
            flux *= mat.kind == MATERIAL_MIRROR ? v3(mat.albedo) : conductorFresnel(mat, cosI);
            event = 3u;
        }
        path = extendPath(path, h.object * 4u + event);
        ++speculars;
        o = offsetOrigin(p, h.normal, d, h.offset);
    }
    causticRays[e.firstRay + i] = ray;
}

#endif
