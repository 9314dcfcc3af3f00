#ifndef LIGHT_MAP_GLSL
#define LIGHT_MAP_GLSL
// Shared visibility for the volume pass (volume.glsl): instead of a shadow
// ray per sample, each pass sees every positional light from one point y on
// it and records, in an octahedral map of the directions around y, the
// distance to the first surface (or other light) that way, traced with the
// renderer's own rays (glass and water included: they block direct light,
// whose refracted part is the caustic passes'). The volume pass then tests
// many points along each camera ray against the map: where the texel and
// its eight neighbours agree (all beyond the point, or all before it), the
// map answers; where they disagree (a shadow's edge) or at the map's folded
// border, a shadow ray does. A shadow edge is thus exact; what the map can
// miss is an occluder thinner than a texel that passes between nine rays.
// The points y follow a Hammersley set over the passes (Cranley–Patterson
// rotated per light and seed), so the soft shadows of an area light converge
// as passes accumulate, and each pass's texels are jittered.
//
// Octahedral maps: Cigolle, Donow, Evangelakos, Mara, McGuire, Meyer, "A
// Survey of Efficient Representations for Independent Unit Vectors", JCGT
// 2014 (an omnidirectional shadow map as in Engelhardt & Dachsbacher,
// "Octahedron Environment Maps", 2008).

#extension GL_EXT_scalar_block_layout : require

#include "random.glsl"
#include "frame.glsl"
#include "light_queries.glsl"

// The includer may qualify the maps' access (the light-map pass writes
// them, the volume pass reads them); unqualified by default.
#ifndef LIGHT_MAPS_ACCESS
#define LIGHT_MAPS_ACCESS
#endif
layout(set = 0, binding = BINDING_LIGHT_MAPS, scalar) LIGHT_MAPS_ACCESS buffer LightMaps { float lightMaps[]; };

// The unit vector w as a point of [0, 1]².
vec2 octEncode(vec3 w) {
    w /= abs(w.x) + abs(w.y) + abs(w.z);
    vec2 e = w.xy;
    if (w.z < 0.0) e = (1.0 - abs(w.yx)) * vec2(w.x >= 0.0 ? 1.0 : -1.0, w.y >= 0.0 ? 1.0 : -1.0);
    return 0.5 * e + 0.5;
}

// The unit vector at f in [0, 1]² (octEncode's inverse).
vec3 octDecode(vec2 f) {
    vec2 e = 2.0 * f - 1.0;
    vec3 w = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-w.z, 0.0);
    w.x += w.x >= 0.0 ? -t : t;
    w.y += w.y >= 0.0 ? -t : t;
    return normalize(w);
}

// Point `i` of the n-point Hammersley set in [0, 1)² ((i + 1/2) / n, and
// the radical inverse of i), shared by the light points and the volume
// pass's camera rays.
vec2 hammersley(uint i, uint n) {
    return vec2((float(i) + 0.5) / float(max(n, 1u)), float(bitfieldReverse(i)) * 2.3283064e-10);
}

// A point on a light: where, its outward normal and the light's area (0
// for a point light, whose `color` is an intensity).
struct LightPoint {
    vec3 p;
    vec3 n;
    float area;
};

// The point on light i that pass `pass` of `passes` sees the light from.
LightPoint passLightPoint(uint i, uint pass, uint passes) {
    uint h = pcgHash(frame.seed ^ pcgHash(i + 0x51ed27u));
    vec2 shift = vec2(float(h >> 8), float(pcgHash(h) >> 8)) * (1.0 / 16777216.0);
    vec2 u = fract(hammersley(pass, passes) + shift);
    Light l = lights[i];
    LightPoint y = LightPoint(v3(l.position), vec3(0.0), 0.0);
    if (l.kind == LIGHT_SPHERE) {
        y.n = sampleUniformSphere(u);
        y.p += l.radius * y.n;
        y.area = 4.0 * PI * l.radius * l.radius;
    } else if (l.kind == LIGHT_RECT) {
        vec3 eu = v3(l.edgeU), ev = v3(l.edgeV), c = cross(eu, ev);
        y.p += u.x * eu + u.y * ev;
        y.area = length(c);
        y.n = c / y.area;
    }
    return y;
}

uint lightMapTexel(uint light, ivec2 t, uint size) { return (light * size + uint(t.y)) * size + uint(t.x); }

// The map's relative margin: a texel's distance within it of the point's
// is neither before nor beyond it.
const float LIGHT_MAP_MARGIN = 1e-3;

#endif
