// Small helpers shared by every shader.
#ifndef COMMON_GLSL
#define COMMON_GLSL

// Scalar-layout float[3] members as vectors.
vec3 v3(float a[3]) { return vec3(a[0], a[1], a[2]); }

#endif
