// Nested dielectrics: a path keeps a stack of the dielectric materials it is
// inside (innermost last). A dielectric surface is an interface between its
// material and the medium on its other side: when the ray enters, the medium
// it comes from (the top of the stack); when it leaves, the medium below
// this material in the stack. Its relative index is the ratio of the two. A
// transmission pushes the material (entering) or removes it (leaving). This
// is right for properly nested objects (a bubble in glass, water in a glass
// vessel); coincident or overlapping interfaces would need priorities
// (Schmidt & Budge 2002). Paths start in vacuum (index 1).
#ifndef STACK_GLSL
#define STACK_GLSL

#include "materials.glsl"
#include "frame.glsl"

const uint MEDIA_STACK = 4u;

struct MediaStack {
    uint material[MEDIA_STACK];
    uint count;
};

MediaStack emptyStack() {
    MediaStack s;
    s.count = 0u;
    return s;
}

// The index of refraction on the far side of material `m`'s surface.
float farSideIor(MediaStack s, uint m, bool entering) {
    if (entering) return s.count > 0u ? materials[s.material[s.count - 1u]].ior : 1.0;
    for (uint k = s.count; k > 0u; --k) { LOOP_EDGE();
        if (s.material[k - 1u] == m) return k > 1u ? materials[s.material[k - 2u]].ior : 1.0;
    }
    return 1.0;
}

// Records a transmission through material `m`'s surface.
void crossInterface(inout MediaStack s, uint m, bool entering) {
    if (entering) {
        if (s.count < MEDIA_STACK) s.material[s.count++] = m;
        return;
    }
    for (uint k = s.count; k > 0u; --k) { LOOP_EDGE();
        if (s.material[k - 1u] == m) {
            for (uint j = k - 1u; j + 1u < s.count; ++j) { LOOP_EDGE(); s.material[j] = s.material[j + 1u]; }
            --s.count;
            return;
        }
    }
}

// The medium a ray inside the stack travels in: the innermost dielectric's
// interior, else the fog (copied field by field, see frame.glsl).
Medium mediumOf(MediaStack s) {
    if (s.count == 0u) return fogMedium();
    uint m = s.material[s.count - 1u];
    Medium med;
    med.density = materials[m].medium.density;
    med.albedo = materials[m].medium.albedo;
    med.anisotropy = materials[m].medium.anisotropy;
    return med;
}

#endif
