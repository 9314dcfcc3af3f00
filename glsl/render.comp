#version 460
// One sample per pixel of a tile: a camera ray, then direct lighting of a
// Lambertian surface from point and sphere lights with shadow rays.
#include "intersect.glsl"
#include "random.glsl"

layout(local_size_x = RENDER_GROUP, local_size_y = RENDER_GROUP) in;

layout(set = 0, binding = BINDING_MATERIALS, scalar) readonly buffer Materials { Material materials[]; };
layout(set = 0, binding = BINDING_LIGHTS, scalar) readonly buffer Lights { Light lights[]; };

// Camera basis: ray direction = forward + x right + y up, x and y in [-1, 1].
layout(set = 0, binding = BINDING_FRAME, scalar) readonly buffer Frame {
    vec3 eye;
    vec3 forward;
    vec3 right;
    vec3 up;
    vec3 background;
    uint width;
    uint height;
    uint seed;
    uint lightCount;
} frame;

// rgb: summed radiance, a: sample count.
layout(set = 0, binding = BINDING_ACCUM, rgba32f) uniform image2D accum;

struct Aov {
    float depth;
    float normal[3];
    float albedo[3];
};
layout(set = 0, binding = BINDING_AOV, scalar) writeonly buffer Aovs { Aov aovs[]; };

layout(push_constant, scalar) uniform Push {
    uvec2 tileOrigin;
    uvec2 tileSize;
    uint sampleIndex;
    uint writeAov;
} pc;

const float PI = 3.14159265358979;

vec3 cameraRay(vec2 pixel) {
    vec2 ndc = vec2(2.0 * pixel.x / float(frame.width) - 1.0, 1.0 - 2.0 * pixel.y / float(frame.height));
    return normalize(frame.forward + ndc.x * frame.right + ndc.y * frame.up);
}

// Offset along the normal that keeps a secondary ray off its own surface.
vec3 offsetOrigin(vec3 p, vec3 n) {
    float scale = max(max(abs(p.x), abs(p.y)), max(abs(p.z), 1.0));
    return p + n * (2e-4 * scale);
}

// Distance to the first intersection with a sphere, or NO_ROOT.
float sphereHit(vec3 o, vec3 d, vec3 c, float r) {
    vec3 oc = o - c;
    float b = dot(oc, d);
    float disc = b * b - (dot(oc, oc) - r * r);
    if (disc < 0.0) return NO_ROOT;
    float s = sqrt(disc);
    float t = -b - s;
    if (t > 0.0) return t;
    t = -b + s;
    return t > 0.0 ? t : NO_ROOT;
}

// Radiance of the sphere lights seen along a ray before distance tmax.
vec3 visibleLights(vec3 o, vec3 d, float tmax) {
    vec3 l = vec3(0.0);
    float best = tmax;
    for (uint i = 0; i < frame.lightCount; ++i) {
        Light li = lights[i];
        if (li.kind != LIGHT_SPHERE) continue;
        float t = sphereHit(o, d, v3(li.position), li.radius);
        if (t < best) { best = t; l = v3(li.color); }
    }
    return l;
}

// Direct lighting at p with normal n (facing the viewer), Lambert BRDF.
vec3 directLight(vec3 p, vec3 n, vec3 albedo, inout uint rng) {
    vec3 sum = vec3(0.0);
    vec3 origin = offsetOrigin(p, n);
    for (uint i = 0; i < frame.lightCount; ++i) {
        Light li = lights[i];
        vec3 c = v3(li.position);
        vec3 toC = c - origin;
        float dist = length(toC);
        if (li.kind == LIGHT_POINT) {
            vec3 wi = toC / dist;
            float cosT = dot(n, wi);
            if (cosT <= 0.0 || occluded(origin, wi, 0.0, dist)) continue;
            sum += v3(li.color) * (cosT / (dist * dist));
        } else {
            // Uniform sampling of the cone of directions the sphere subtends.
            if (dist <= li.radius) continue;
            float sinMax2 = (li.radius * li.radius) / (dist * dist);
            float cosMax = sqrt(max(0.0, 1.0 - sinMax2));
            vec2 u = rand2(rng);
            float cosA = 1.0 - u.x * (1.0 - cosMax);
            float sinA = sqrt(max(0.0, 1.0 - cosA * cosA));
            float phi = 2.0 * PI * u.y;
            vec3 w = toC / dist;
            vec3 a = abs(w.x) > 0.9 ? vec3(0, 1, 0) : vec3(1, 0, 0);
            vec3 tu = normalize(cross(a, w));
            vec3 tv = cross(w, tu);
            vec3 wi = normalize(cosA * w + sinA * (cos(phi) * tu + sin(phi) * tv));
            float cosT = dot(n, wi);
            if (cosT <= 0.0) continue;
            float tl = sphereHit(origin, wi, c, li.radius);
            if (tl == NO_ROOT || occluded(origin, wi, 0.0, tl)) continue;
            float pdf = 1.0 / (2.0 * PI * (1.0 - cosMax));
            sum += v3(li.color) * (cosT / pdf);
        }
    }
    return sum * albedo / PI;
}

void main() {
    uvec2 local = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(local, pc.tileSize))) return;
    uvec2 pix = pc.tileOrigin + local;
    uint idx = pix.y * frame.width + pix.x;
    uint rng = seedRandom(pix, pc.sampleIndex, frame.seed);

    if (pc.writeAov != 0u) {
        // AOVs from the ray through the pixel centre.
        vec3 d = cameraRay(vec2(pix) + 0.5);
        SceneHit h = traceScene(frame.eye, d, 0.0, 1e30);
        Aov aov;
        aov.depth = h.object == NO_HIT ? 1.0 / 0.0 : h.t;
        vec3 n = h.normal;
        aov.normal = float[3](n.x, n.y, n.z);
        vec3 alb = h.object == NO_HIT ? vec3(0.0) : v3(materials[objects[h.object].material].albedo);
        aov.albedo = float[3](alb.x, alb.y, alb.z);
        aovs[idx] = aov;
    }

    vec3 d = cameraRay(vec2(pix) + rand2(rng));
    SceneHit h = traceScene(frame.eye, d, 0.0, 1e30);
    vec3 radiance;
    if (h.object == NO_HIT) {
        radiance = frame.background + visibleLights(frame.eye, d, 1e30);
    } else {
        vec3 lightSeen = visibleLights(frame.eye, d, h.t);
        if (lightSeen != vec3(0.0)) {
            radiance = lightSeen;
        } else {
            Material m = materials[objects[h.object].material];
            vec3 p = frame.eye + h.t * d;
            vec3 n = dot(h.normal, d) > 0.0 ? -h.normal : h.normal;
            radiance = v3(m.emission) + directLight(p, n, v3(m.albedo), rng);
        }
    }
    // No NaN or Inf ever leaves the renderer.
    if (any(isnan(radiance)) || any(isinf(radiance))) radiance = vec3(0.0);
    ivec2 at = ivec2(pix);
    imageStore(accum, at, imageLoad(accum, at) + vec4(radiance, 1.0));
}
