// The environment seen by the path tracer (render.glsl): a lat-long map
// (envmap.glsl samples it by luminance) or the uniform background radiance,
// looked up, and its pdf for multiple importance sampling.
#ifndef ENVIRONMENT_GLSL
#define ENVIRONMENT_GLSL

#include "render_inputs.glsl"

// ---- The environment map --------------------------------------------------
layout(set = 0, binding = BINDING_ENV_CDF, scalar) readonly buffer EnvCdf { float envCdf[]; };

float envCdfAt(uint i) { return envCdf[i]; }
vec3 envTexelRadiance(ivec2 t) {
    return texelFetch(textures[nonuniformEXT(frame.envMap)], t, 0).rgb * frame.envScale;
}
#include "envmap.glsl"

bool envMapped() { return frame.envMap != NO_TEXTURE; }

vec3 environmentRadiance(vec3 d) {
    return envMapped() ? envTexelRadiance(envTexelAt(directionToUv(d), frame.envWidth, frame.envHeight))
                       : frame.background;
}

float environmentPdf(vec3 d) {
    return envMapped() ? envMapPdf(d, frame.envWidth, frame.envHeight) : 1.0 / (4.0 * PI);
}

#endif
