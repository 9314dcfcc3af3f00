// Tracing without ray-tracing extensions (the `compute` backend): the
// project's own four-wide BVH over every object's cells (src/passes/bvh.rs
// builds it on the host with binned SAH), walked nearest child first with a
// short stack; each leaf's cells are searched by the same closerRoot as the
// ray-query path's candidate loop (candidate.glsl). Shadow rays stop at the
// first root. The boxes are the cells' object-space boxes mapped to the GPU's
// world frame (padded as the hardware's are for far objects), so every cell
// the ray-query backend would search is searched here too.
#ifndef TRAVERSE_COMPUTE_GLSL
#define TRAVERSE_COMPUTE_GLSL

#include "root_search.glsl"
#include "hit.glsl"
#include "candidate.glsl"

// Four child boxes (world frame, structure of arrays) and what each is: an
// inner node's index, a leaf (BVH_LEAF set: BVH_LEAF_SHIFT bits of count - 1
// above the first primitive) or BVH_EMPTY.
struct BvhNode {
    vec4 loX, loY, loZ;
    vec4 hiX, hiY, hiZ;
    uvec4 child;
};

// A leaf primitive: one cell of one object.
struct BvhPrimitive {
    uint object;
    uint cell;
};

layout(set = 0, binding = BINDING_BVH_NODES, scalar) readonly buffer BvhNodes { BvhNode bvhNodes[]; };
// An object's world-to-object map in f32 (row-major 3x4).
struct BvhObject {
    vec4 rows[3];
};

layout(set = 0, binding = BINDING_BVH_PRIMITIVES, scalar) readonly buffer BvhPrimitives { BvhPrimitive bvhPrimitives[]; };
layout(set = 0, binding = BINDING_BVH_OBJECTS, scalar) readonly buffer BvhObjects { BvhObject bvhObjects[]; };

// The stack of nodes still to visit: each level pushes at most the 3
// children it does not visit next, and the host builds trees of at most
// MAX_DEPTH levels (src/passes/bvh.rs), so it never overflows.
const uint BVH_STACK_SIZE = BVH_STACK;
const float BVH_MISS = 3.0e38;

// The entry distance of o + t d into each of a node's four boxes within
// [tmin, tmax], BVH_MISS where it misses one (or the slot is empty). `inv`
// is 1 / d with no infinite component.
vec4 childEntries(BvhNode n, vec3 o, vec3 inv, float tmin, float tmax) {
    vec4 x0 = (n.loX - o.x) * inv.x, x1 = (n.hiX - o.x) * inv.x;
    vec4 y0 = (n.loY - o.y) * inv.y, y1 = (n.hiY - o.y) * inv.y;
    vec4 z0 = (n.loZ - o.z) * inv.z, z1 = (n.hiZ - o.z) * inv.z;
    vec4 near = max(max(min(x0, x1), min(y0, y1)), max(min(z0, z1), vec4(tmin)));
    vec4 far = min(min(max(x0, x1), max(y0, y1)), min(max(z0, z1), vec4(tmax)));
    bvec4 hit = bvec4(uvec4(lessThanEqual(near, far)) & uvec4(notEqual(n.child, uvec4(BVH_EMPTY))));
    return mix(vec4(BVH_MISS), near, hit);
}

// The linear part and translation of object `object`'s world-to-object map,
// rounded to f32 from its f64 form on the host (rows of a 3x4 matrix).
void objectMap(uint object, out mat3 l, out vec3 c) {
    vec4 r0 = bvhObjects[object].rows[0], r1 = bvhObjects[object].rows[1], r2 = bvhObjects[object].rows[2];
    l = transpose(mat3(r0.xyz, r1.xyz, r2.xyz));
    c = vec3(r0.w, r1.w, r2.w);
}

// Swaps entries i and j of the child list when j is the farther: sorts
// the four children far to near, so the nearest is pushed last.
#define BVH_ORDER(i, j)                                  \
    if (t[i] < t[j]) {                                   \
        float ft = t[i]; t[i] = t[j]; t[j] = ft;         \
        uint fc = c[i]; c[i] = c[j]; c[j] = fc;          \
    }

// The closest hit of o + t d, t in [tmin, tmax] (world space); with
// `anyHit`, any hit, with only its t and object (a shadow ray).
SceneHit traceSceneWith(vec3 o, vec3 d, float tmin, float tmax, bool anyHit) {
    // 1 / d, with components below 1e-20 in size taken as 1e-20 (signed), so
    // that no slab distance is 0 · inf.
    vec3 safe = mix(d, mix(vec3(-1e-20), vec3(1e-20), greaterThanEqual(d, vec3(0.0))), lessThan(abs(d), vec3(1e-20)));
    vec3 inv = 1.0 / safe;
    float best = tmax;
    double best64 = double(tmax);
    vec3 bestPoint = vec3(0.0);
    uint hitObject = NO_HIT, hitCell = 0u;
    mat3 hitMap = mat3(1.0);
    uint stackChild[BVH_STACK_SIZE];
    float stackEntry[BVH_STACK_SIZE];
    uint top = 0u;
    // The node or leaf visited next (the root first); BVH_EMPTY when the
    // stack must be popped.
    uint child = 0u;
    while (true) { LOOP_EDGE();
        if (child == BVH_EMPTY) {
            if (top == 0u) break;
            --top;
            if (stackEntry[top] > best) continue;
            child = stackChild[top];
        }
        if ((child & BVH_LEAF) != 0u) {
            uint first = child & BVH_FIRST_MASK, count = ((child & ~BVH_LEAF) >> BVH_LEAF_SHIFT) + 1u;
            child = BVH_EMPTY;
            for (uint i = first; i < first + count; ++i) { LOOP_EDGE();
                BvhPrimitive p = bvhPrimitives[i];
                mat3 l;
                vec3 c;
                objectMap(p.object, l, c);
                if (closerRoot(p.object, p.cell, l * o + c, l * d, o, d, tmin, best, best64, bestPoint)) {
                    hitObject = p.object;
                    hitCell = p.cell;
                    hitMap = l;
                    if (anyHit) break;
                }
            }
            if (anyHit && hitObject != NO_HIT) break;
            continue;
        }
        BvhNode n = bvhNodes[child];
        vec4 entries = childEntries(n, o, inv, tmin, best);
        float t[4] = float[4](entries.x, entries.y, entries.z, entries.w);
        uint c[4] = uint[4](n.child.x, n.child.y, n.child.z, n.child.w);
        BVH_ORDER(0, 1) BVH_ORDER(2, 3) BVH_ORDER(0, 2) BVH_ORDER(1, 3) BVH_ORDER(1, 2)
        // The nearest child is visited next; the others wait on the stack.
        child = t[3] < BVH_MISS ? c[3] : BVH_EMPTY;
        [[unroll]] for (int k = 0; k < 3; ++k) {
            if (t[k] < BVH_MISS) {
                stackChild[top] = c[k];
                stackEntry[top] = t[k];
                ++top;
            }
        }
    }
    SceneHit h = noHit();
    if (hitObject == NO_HIT) return h;
    h.t = best;
    h.object = hitObject;
    if (anyHit) return h;
    h.cell = hitCell;
    h.objectPoint = bestPoint;
    completeHit(h, o, d, hitMap);
    return h;
}

// The closest hit of o + t d, t in [tmin, tmax] (world space).
SceneHit traceScene(vec3 o, vec3 d, float tmin, float tmax) { return traceSceneWith(o, d, tmin, tmax, false); }

// True when something blocks o + t d for t in [tmin, tmax].
bool occluded(vec3 o, vec3 d, float tmin, float tmax) { return traceSceneWith(o, d, tmin, tmax, true).object != NO_HIT; }

#endif
