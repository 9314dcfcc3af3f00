// The scene's texture maps with their mip chains (unused slots hold a white
// texel), indexed by a material's map slots; read by the render pass and the
// texture probes.
#ifndef TEXTURE_MAPS_GLSL
#define TEXTURE_MAPS_GLSL

#extension GL_EXT_nonuniform_qualifier : require

layout(set = 0, binding = BINDING_TEXTURES) uniform sampler2D textures[MAX_TEXTURES];

// Map `index` at uv, bilinear on level 0 (what FILTER_NONE reads).
vec4 mapAt(uint index, vec2 uv) { return textureLod(textures[nonuniformEXT(index)], uv, 0.0); }

#endif
