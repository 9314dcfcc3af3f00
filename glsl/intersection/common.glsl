// Small helpers shared by every shader.
#ifndef COMMON_GLSL
#define COMMON_GLSL

// One pass through a loop's body for the loop-budget counter: counted in
// the tracing shaders, which include loop_budget.glsl first; empty elsewhere.
#ifndef LOOP_EDGE
#define LOOP_EDGE()
#endif

const float PI = 3.14159265358979;

// "No root / no hit" distance.
const float NO_ROOT = 3.402823e38;

// Scalar-layout float[3] members as vectors.
vec3 v3(float a[3]) { return vec3(a[0], a[1], a[2]); }

// An orthonormal basis around n (Duff et al., "Building an Orthonormal Basis,
// Revisited", JCGT 2017).
mat3 frameAround(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
    return mat3(t, bt, n);  // columns: local x, y, z
}

#endif
