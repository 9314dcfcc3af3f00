// What a path carries from vertex to vertex (render.glsl, tracePath), and
// how it starts.
#ifndef PATH_STATE_GLSL
#define PATH_STATE_GLSL

#include "render_inputs.glsl"
#include "stack.glsl"
#include "path_footprint.glsl"
#include "camera.glsl"
#include "roulette.glsl"

// A scattering event in a medium, for the weight of a positional light that
// the sampled direction reaches: the segment it was on (origin, end
// distance; direction), where on it, and the density σ_t T(t) there.
struct MediumScatter {
    vec4 segment;
    vec3 dir;
    float t;
    float density;
};

// The denoiser's auxiliary features of one path (Intel Open Image
// Denoise's albedo and normal images): taken at the path's first vertex that
// is not a perfect specular one, so that a texture seen through glass or in
// a mirror shows in them as it does in the image (Cycles' denoising passes
// do the same), times the colour of the specular vertices on the way.
struct DenoiseFeatures {
    vec3 tint;  // the product of the specular vertices' colours so far
    vec3 albedo;
    vec3 normal;
    bool open;  // true until the features are taken
};

// The state of a path between two of its segments.
struct PathState {
    vec3 o;  // the next segment's origin
    vec3 d;  // and direction
    vec3 radiance;
    vec3 throughput;
    // The product of the η² factors refractions divided the throughput by
    // (Russian roulette's survival probability uses throughput × etaScale).
    float etaScale;
    float lastPdf;  // solid-angle pdf of the last BSDF sample; 0 after a delta lobe or the camera
    vec3 lastPoint;
    // After a scattering event in a medium: where it was (0 density after
    // any other vertex).
    MediumScatter scatter;
    // Caustic paths: true while the path has gone from the primary receiver
    // through the specular vertices that the caustic map covers; their count.
    bool causticPath;
    uint causticSpeculars;
    // True once such a path has reflected off glass (the caustic rays'
    // reflecting grids cover that reflection as the last vertex before the
    // light only).
    bool causticReflected;
    // True when the last scattering event was on the camera ray's first
    // segment and the volume pass covers it (VOLUME_ENABLED).
    bool scatteredOnVolumeSegment;
    // Scattering events so far (surfaces and media; an index-matched
    // interface is not one), and segments traced (every interface counts).
    uint bounce;
    uint step;
    bool alive;
    MediaStack media;
    // The footprint (ray cone or covariance, path_footprint.glsl).
    PathFootprint foot;
    DenoiseFeatures features;
};

// A path leaving the camera at o along d; its footprint starts as its share
// of the pixel filter (cameraJitter).
PathState pathStart(vec3 o, vec3 d) {
    float pixelAngle = 2.0 * length(frame.up) / float(frame.height);
    PathFootprint foot = footprintAtCamera(d, footprintSigma() * pixelAngle);
    return PathState(o, d, vec3(0.0), vec3(1.0), 1.0, 0.0, o, MediumScatter(vec4(0.0), vec3(0.0), 0.0, 0.0), false, 0u,
                     false, false, 0u, 0u, true, emptyStack(), foot,
                     DenoiseFeatures(vec3(1.0), vec3(0.0), vec3(0.0), true));
}

// Takes the denoiser's features at this vertex (albedo clamped to [0, 1],
// as the denoiser expects), unless an earlier vertex gave them.
void takeFeatures(inout PathState s, vec3 albedo, vec3 normal) {
    if (!s.features.open) return;
    s.features.albedo = s.features.tint * clamp(albedo, 0.0, 1.0);
    s.features.normal = normal;
    s.features.open = false;
}

// True at the path's last vertex (its continuation only looks for an
// emitter; no Russian roulette there).
bool lastVertex(PathState s) { return s.bounce + 1u == frame.maxDepth; }

// Russian roulette after a surface's scattering event (a medium's comes
// before its direction is chosen: mediumEvent), then the next bounce.
void nextBounce(inout PathState s, inout PathSampler rng) {
    if (!lastVertex(s) && !survives(s.throughput, s.etaScale, s.bounce, rng)) s.alive = false;
    ++s.bounce;
}

#endif
