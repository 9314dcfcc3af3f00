// Shared by light_map.comp (ray queries) and light_map.rgen (pipeline
// backend): one texel of light `pc.light`'s map for pass `pc.pass`
// (light_map.glsl): the distance from the pass's point on the light along
// the texel's direction (jittered within the texel) to the first surface
// or other light; 0 toward the light's back (nothing leaves it that way).
#extension GL_EXT_nonuniform_qualifier : require

#include "intersect.glsl"
#include "lights.glsl"
#include "materials.glsl"

#include "frame.glsl"
#include "light_queries.glsl"

#define LIGHT_MAPS_ACCESS writeonly
#include "light_map.glsl"

layout(push_constant, scalar) uniform PushBlock { LightMapPush pc; };

void lightMapAt(uvec2 texel) {
    uint size = pc.mapSize;
    if (texel.x >= size || texel.y >= size) return;
    LightPoint y = passLightPoint(pc.light, pc.pass, pc.passes);
    uint rng = seedRandom(texel, 0x11a70000u + pc.pass, frame.seed ^ pc.light);
    vec3 w = octDecode((vec2(texel) + rand2(rng)) / float(size));
    float depth = 0.0;
    if (y.area == 0.0 || dot(w, y.n) > 0.0) {
        SceneHit h = traceScene(y.p, w, 0.0, 1e30);
        depth = h.object == NO_HIT ? 1e30 : h.t;
        float tl;
        firstLightHit(y.p, w, depth, pc.light, tl);
        depth = min(depth, tl);
    }
    lightMaps[lightMapTexel(pc.light, ivec2(texel), size)] = depth;
}
