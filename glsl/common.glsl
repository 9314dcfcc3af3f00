// Small helpers shared by every shader.
#ifndef COMMON_GLSL
#define COMMON_GLSL

// "No root / no hit" distance.
const float NO_ROOT = 3.402823e38;

// Scalar-layout float[3] members as vectors.
vec3 v3(float a[3]) { return vec3(a[0], a[1], a[2]); }

#endif
