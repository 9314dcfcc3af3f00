#version 460
// Surface caustics from neighbouring rays (paper section 3; compare Ernst,
// Akenine-Möller & Jensen 2005, "Interactive rendering of caustics using
// interpolated warped volumes"). Four neighbouring rays of an emission grid
// that followed the same sequence of surfaces form a caustic cell; its
// landing quad (two triangles) is where their flux went. Each ray's
// irradiance is its flux over the mean area of the valid cells around it
// (the area function, averaged over the rays), and inside a cell the
// irradiance is interpolated linearly between its corners: smooth, without
// the noise of photon splatting at the same ray count.
//
// One invocation per cell: the cell is projected into the image and every
// pixel whose G-buffer receiver lies in it (same object, in a triangle, near
// its plane) gets the interpolated irradiance, added with 64-bit integer
// atomics in fixed point (cells overlap where the caustic folds).
#extension GL_EXT_shader_atomic_int64 : require
// This pass traces no rays.
#define NO_TRACING
#include "interface.glsl"
#include "frame.glsl"
#include "caustics.glsl"
#include "balance.glsl"

layout(set = 0, binding = BINDING_CAUSTIC_RAYS, scalar) buffer CausticRays { CausticRay causticRays[]; };
layout(set = 0, binding = BINDING_GBUFFER, scalar) buffer Receivers { Receiver receivers[]; };

layout(local_size_x = CAUSTIC_GROUP) in;

// Per pixel: irradiance × CAUSTIC_FIXED_POINT in R, G, B.
layout(set = 0, binding = BINDING_CAUSTIC_MAP, scalar) buffer CausticMap { uint64_t causticMap[]; };

layout(push_constant, scalar) uniform PushBlock { CausticPush pc; };

CausticRay rayAt(ivec2 g) { return causticRays[pc.emitter.firstRay + uint(g.y) * pc.emitter.grid.x + uint(g.x)]; }

vec3 landing(ivec2 g) { return v3(rayAt(g).position); }

// True when the four rays at the corners of cell c (its lowest corner) are
// valid and followed the same path.
bool cellValid(ivec2 c) {
    if (any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c + 1, ivec2(pc.emitter.grid)))) return false;
    uint p = rayAt(c).path;
    return p != 0u && rayAt(c + ivec2(1, 0)).path == p && rayAt(c + ivec2(0, 1)).path == p
        && rayAt(c + ivec2(1, 1)).path == p;
}

// Area of cell c's landing quad, as two triangles (00, 10, 11) and (00, 11, 01).
float cellArea(ivec2 c) {
    vec3 p00 = landing(c), p10 = landing(c + ivec2(1, 0)), p01 = landing(c + ivec2(0, 1));
    vec3 p11 = landing(c + ivec2(1, 1));
    return 0.5 * (length(cross(p10 - p00, p11 - p00)) + length(cross(p11 - p00, p01 - p00)));
}

// Irradiance at ray g's landing: its flux over the mean area of the valid
// cells it is a corner of (each ray stands for one grid cell's worth of
// emission, and its four cells share it out).
vec3 rayIrradiance(ivec2 g) {
    float area = 0.0;
    float cells = 0.0;
    for (int dy = -1; dy <= 0; ++dy) {
        for (int dx = -1; dx <= 0; ++dx) {
            ivec2 c = g + ivec2(dx, dy);
            if (!cellValid(c)) continue;
            area += cellArea(c);
            cells += 1.0;
        }
    }
    return area > 0.0 ? v3(rayAt(g).flux) * (cells / area) : vec3(0.0);
}

// Barycentric coordinates of x in triangle (a, b, c), and x's distance from
// its plane in w; w < 0 for a degenerate triangle.
vec4 barycentric(vec3 x, vec3 a, vec3 b, vec3 c) {
    vec3 n = cross(b - a, c - a);
    float nn = dot(n, n);
    if (!(nn > 0.0)) return vec4(0.0, 0.0, 0.0, -1.0);
    float la = dot(cross(c - b, x - b), n) / nn;
    float lb = dot(cross(a - c, x - c), n) / nn;
    return vec4(la, lb, 1.0 - la - lb, abs(dot(x - a, n)) / sqrt(nn));
}

void addIrradiance(uint pixel, vec3 e) {
    u64vec3 fixedPoint = u64vec3(e * float(CAUSTIC_FIXED_POINT) + 0.5);
    atomicAdd(causticMap[3u * pixel], fixedPoint.x);
    atomicAdd(causticMap[3u * pixel + 1u], fixedPoint.y);
    atomicAdd(causticMap[3u * pixel + 2u], fixedPoint.z);
}

void main() {
    uvec2 grid = pc.emitter.grid;
    uint i = balancedIndex(CAUSTIC_GROUP);
    if (grid.x < 2u || grid.y < 2u || i >= (grid.x - 1u) * (grid.y - 1u)) return;
    ivec2 c = ivec2(i % (grid.x - 1u), i / (grid.x - 1u));
    if (!cellValid(c)) return;
    ivec2 corner[4] = ivec2[4](c, c + ivec2(1, 0), c + ivec2(1, 1), c + ivec2(0, 1));
    vec3 p[4];
    vec3 e[4];
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    float edge = 0.0;
    for (int k = 0; k < 4; ++k) {
        p[k] = landing(corner[k]);
        e[k] = rayIrradiance(corner[k]);
        vec2 px;
        if (!project(p[k], px)) return;
        lo = min(lo, px);
        hi = max(hi, px);
        edge = max(edge, length(p[k] - p[(k + 1) % 4]));
    }
    // Receivers within this distance of a triangle's plane belong to it
    // (curved receivers sag between the corners).
    float tolerance = 0.25 * edge + 1e-6;
    uint object = rayAt(c).object;
    ivec2 first = max(ivec2(floor(lo - 0.5)), ivec2(0));
    ivec2 last = min(ivec2(ceil(hi - 0.5)), ivec2(frame.width, frame.height) - 1);
    for (int y = first.y; y <= last.y; ++y) {
        for (int x = first.x; x <= last.x; ++x) {
            uint pixel = uint(y) * frame.width + uint(x);
            Receiver r = receivers[pixel];
            if (r.object != object) continue;
            vec3 g = v3(r.position);
            for (int t = 0; t < 2; ++t) {
                int b = t == 0 ? 1 : 2, d = t == 0 ? 2 : 3;
                vec4 l = barycentric(g, p[0], p[b], p[d]);
                if (l.w < 0.0 || l.w > tolerance || any(lessThan(l.xyz, vec3(-1e-5)))) continue;
                addIrradiance(pixel, l.x * e[0] + l.y * e[b] + l.z * e[d]);
                break;
            }
        }
    }
}
