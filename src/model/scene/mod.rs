//! The scene a renderer consumes: camera, image settings, materials,
//! functional objects with transforms, and lights. `file.rs` reads it from
//! TOML (documented field by field in `scenes/README.md`).

pub mod file;
pub mod maps;
pub mod preset;

use glam::{DAffine3, DVec3, Vec3};

pub use crate::model::geometry::uv::{UvMapping, UvSettings};
use crate::model::geometry::FunctionalObject;
pub use crate::model::texture::TextureImage;

pub use file::{load_scene, parse_scene, SceneError, DEFAULT_SCENE, DEFAULT_SCENE_NAME, MAX_IMAGE_SIZE, MAX_SPP};

/// The longest path a scene may ask for (`image.max_depth`).
pub const MAX_DEPTH: u32 = file::MAX_DEPTH as u32;
pub use preset::{DenoiseQuality, FilterMode, Preset, Quality};

/// A pinhole camera.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Camera {
    /// Eye position in world space.
    pub position: DVec3,
    /// The point the camera looks at.
    pub look_at: DVec3,
    /// Up direction (need not be orthogonal to the view direction).
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub vfov_degrees: f64,
    /// Camera keyframes (`[[camera.keyframes]]`), in increasing time; empty
    /// for a still camera. [`Scene::at_frame`] interpolates them.
    pub keyframes: Vec<CameraKeyframe>,
    /// Frames per second of the animation (`camera.fps`, default 24):
    /// frame F is at time F / fps.
    pub fps: f64,
}

/// A camera keyframe: where the camera is at `time` seconds.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CameraKeyframe {
    /// Time in seconds.
    pub time: f64,
    /// Eye position.
    pub position: DVec3,
    /// The point looked at.
    pub look_at: DVec3,
    /// Up direction.
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub vfov_degrees: f64,
}

impl Camera {
    /// A still camera (no keyframes, 24 frames per second).
    pub fn still(position: DVec3, look_at: DVec3, up: DVec3, vfov_degrees: f64) -> Self {
        Self { position, look_at, up, vfov_degrees, keyframes: Vec::new(), fps: 24.0 }
    }

    /// The camera at frame `frame`: its keyframes interpolated linearly
    /// (position, look_at, up and fov) at time frame / fps, held before the
    /// first and after the last; itself when it has no keyframes.
    pub fn at_frame(&self, frame: u32) -> Self {
        let (Some(first), Some(last)) = (self.keyframes.first(), self.keyframes.last()) else {
            return self.clone();
        };
        let t = frame as f64 / self.fps;
        let (a, b, s) = if t <= first.time {
            (first, first, 0.0)
        } else if t >= last.time {
            (last, last, 0.0)
        } else {
            let i = self.keyframes.partition_point(|k| k.time <= t);
            let (a, b) = (&self.keyframes[i - 1], &self.keyframes[i]);
            (a, b, (t - a.time) / (b.time - a.time))
        };
        Self {
            position: a.position.lerp(b.position, s),
            look_at: a.look_at.lerp(b.look_at, s),
            up: a.up.lerp(b.up, s),
            vfov_degrees: a.vfov_degrees + (b.vfov_degrees - a.vfov_degrees) * s,
            keyframes: self.keyframes.clone(),
            fps: self.fps,
        }
    }

    /// The origin of the GPU scene's coordinates for renders of this camera:
    /// the first keyframe's position for an animated camera (the same in
    /// every frame, so that a frame renders the same alone or in a range),
    /// else the camera's position.
    pub fn render_origin(&self) -> DVec3 {
        self.keyframes.first().map_or(self.position, |k| k.position)
    }
}

/// Image size, sampling and exposure.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ImageSettings {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Seed of the per-pixel random sequences.
    pub seed: u32,
    /// Exposure in stops applied before tone mapping the PNG.
    pub exposure: f32,
    /// Longest light path, in bounces (1 = direct lighting only).
    pub max_depth: u32,
    /// Texture filtering.
    pub filter: FilterMode,
    /// The quality preset the settings started from, if any (the scene
    /// file's or the command line's; explicit settings may override parts).
    pub preset: Option<Preset>,
    /// Denoise the finished image (Intel Open Image Denoise; the raw
    /// radiance is kept in the EXR). Not part of the render's key: a
    /// checkpoint or tile of the same render with or without it matches.
    pub denoise: bool,
    /// The denoiser's quality.
    pub denoise_quality: DenoiseQuality,
}

impl ImageSettings {
    /// `width` x `height`, one sample per pixel, seed 0, exposure 0,
    /// direct lighting only (`max_depth` 1), no filtering, no preset: the
    /// settings of scenes built in code (tests, benchmarks), which change
    /// what they need.
    pub fn minimal(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            spp: 1,
            seed: 0,
            exposure: 0.0,
            max_depth: 1,
            filter: FilterMode::default(),
            preset: None,
            denoise: false,
            denoise_quality: DenoiseQuality::default(),
        }
    }
}

/// How a surface scatters light.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum MaterialKind {
    /// Lambertian reflection of [`Material::albedo`].
    Diffuse,
    /// A GGX microfacet metal (Smith height-correlated masking, visible-normal
    /// sampling).
    Conductor {
        /// Perceptual roughness in [0, 1]; the GGX α is roughness².
        roughness: f32,
        /// The conductor's Fresnel reflectance.
        fresnel: ConductorFresnel,
    },
    /// Glass or water: Fresnel reflection and refraction, smooth when
    /// `roughness` is 0, GGX rough otherwise (Walter et al. 2007).
    Dielectric {
        /// Perceptual roughness in [0, 1].
        roughness: f32,
        /// Index of refraction of the inside relative to vacuum (> 0).
        ior: f32,
    },
    /// A perfect mirror reflecting [`Material::albedo`].
    Mirror,
}

/// Fresnel reflectance of a conductor.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum ConductorFresnel {
    /// Exact conductor Fresnel from the complex index of refraction η + iκ per RGB channel.
    Complex {
        /// Real part η.
        eta: Vec3,
        /// Extinction κ.
        k: Vec3,
    },
    /// Schlick's approximation from the reflectance at normal incidence
    /// (an artist colour).
    Schlick {
        /// Reflectance at normal incidence.
        f0: Vec3,
    },
}

/// A material: how it scatters light, and what it emits.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Material {
    /// Name used by objects to refer to it.
    pub name: String,
    /// Scattering model.
    pub kind: MaterialKind,
    /// Diffuse reflectance (diffuse) or reflectance (mirror); linear RGB, each in [0, 1].
    pub albedo: Vec3,
    /// Emitted radiance (linear RGB).
    pub emission: Vec3,
    /// Texture maps (indices into [`Scene::textures`]).
    pub maps: MaterialMaps,
    /// The participating medium filling the inside of a dielectric (water),
    /// if any; clear when `None`.
    pub medium: Option<Medium>,
}

/// A homogeneous participating medium (Henyey–Greenstein phase function).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Medium {
    /// Extinction coefficient σ_t (per unit length), the same for every
    /// colour: light travels 1 / density on average before it scatters or is
    /// absorbed.
    pub density: f32,
    /// Single-scattering albedo σ_s / σ_t per RGB channel, each in [0, 1];
    /// the rest of the extinction is absorption.
    pub albedo: Vec3,
    /// Henyey–Greenstein asymmetry g in [−0.99, 0.99]: > 0 forward, < 0
    /// backward, 0 isotropic scattering.
    pub anisotropy: f32,
}

/// The texture maps of a material, as indices into [`Scene::textures`].
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct MaterialMaps {
    /// Colour map: multiplies `albedo` (sRGB-decoded RGB).
    pub albedo: Option<usize>,
    /// Tangent-space normal map (RGB = (n + 1) / 2, linear).
    pub normal: Option<usize>,
    /// Roughness map (R channel, linear): replaces the material's roughness.
    pub roughness: Option<usize>,
    /// Displacement (height) map (R channel, linear, in [0, 1]) and its
    /// height scale in world units. Shading only: it tilts the shading
    /// normal (bump mapping); the surface F' = 0 itself does not move.
    pub displacement: Option<(usize, f32)>,
}

impl Material {
    /// A Lambertian material.
    pub fn diffuse(name: &str, albedo: Vec3) -> Self {
        Self {
            name: name.into(),
            kind: MaterialKind::Diffuse,
            albedo,
            emission: Vec3::ZERO,
            maps: MaterialMaps::default(),
            medium: None,
        }
    }
}

/// A functional object placed in the world.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SceneObject {
    /// Name, for messages.
    pub name: String,
    /// The surface in its own frame.
    pub shape: FunctionalObject,
    /// Object-to-world transform.
    pub transform: DAffine3,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Texture coordinates.
    pub uv: UvSettings,
}

/// A light source.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum Light {
    /// An isotropic point light of the given radiant intensity (W/sr, RGB).
    Point {
        /// Position.
        position: DVec3,
        /// Radiant intensity.
        intensity: Vec3,
    },
    /// A spherical area light emitting uniform radiance from its surface.
    Sphere {
        /// Centre.
        centre: DVec3,
        /// Radius (> 0).
        radius: f64,
        /// Emitted radiance.
        radiance: Vec3,
    },
    /// A one-sided parallelogram light: points `corner + a edge_u + b edge_v`,
    /// a and b in [0, 1], emitting toward `edge_u × edge_v`.
    Rect {
        /// One corner.
        corner: DVec3,
        /// First edge.
        edge_u: DVec3,
        /// Second edge.
        edge_v: DVec3,
        /// Emitted radiance.
        radiance: Vec3,
    },
    /// A distant light (the sun): parallel light arriving from `direction`.
    Directional {
        /// Unit direction from the scene toward the light.
        direction: DVec3,
        /// Irradiance on a surface facing the light (W/m²).
        irradiance: Vec3,
    },
}

/// A whole scene.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Scene {
    /// Image settings.
    pub image: ImageSettings,
    /// Camera.
    pub camera: Camera,
    /// Radiance arriving from infinity in every direction (linear RGB): what
    /// rays that hit nothing see, and a uniform environment light.
    pub background: Vec3,
    /// Materials.
    pub materials: Vec<Material>,
    /// Objects.
    pub objects: Vec<SceneObject>,
    /// Lights.
    pub lights: Vec<Light>,
    /// Texture maps used by the materials (and the environment map).
    pub textures: Vec<TextureImage>,
    /// An environment map replacing the uniform `background`, if any.
    pub environment: Option<EnvironmentMapSettings>,
    /// A medium filling all space outside the objects (fog), if any.
    pub fog: Option<Medium>,
    /// The caustic passes' settings (`[caustics]`).
    pub caustics: CausticSettings,
    /// The volume pass's settings (`[volume]`).
    pub volume: VolumeSettings,
}

/// Settings of the volumetric-lighting pass (`[volume]` in a scene file).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct VolumeSettings {
    /// Camera rays per pixel and per sample of the render (so the volume
    /// pass converges with the render) along which single scattering toward
    /// the positional lights is estimated (0: no volume pass; the path
    /// tracer then estimates it).
    pub samples: u32,
}

/// Default `[volume] samples`.
pub const DEFAULT_VOLUME_SAMPLES: u32 = 1;

impl Default for VolumeSettings {
    fn default() -> Self {
        Self { samples: DEFAULT_VOLUME_SAMPLES }
    }
}

/// Settings of the caustic passes (`[caustics]` in a scene file).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CausticSettings {
    /// Caustic rays per light and light sample (0: no caustic passes; the
    /// path tracer then estimates caustics by brute force).
    pub rays: u32,
    /// Points on each sphere light from which the rays are emitted (its
    /// extent softens the caustics); point and directional lights use one.
    pub light_samples: u32,
}

/// Default `[image] max_depth`.
pub const DEFAULT_MAX_DEPTH: u32 = 6;

/// Default `[caustics] rays`.
pub const DEFAULT_CAUSTIC_RAYS: u32 = 65536;
/// Default `[caustics] light_samples`.
pub const DEFAULT_CAUSTIC_LIGHT_SAMPLES: u32 = 16;

impl Default for CausticSettings {
    fn default() -> Self {
        Self { rays: DEFAULT_CAUSTIC_RAYS, light_samples: DEFAULT_CAUSTIC_LIGHT_SAMPLES }
    }
}

/// Below this GGX α (roughness²) a lobe is a perfect specular (delta) lobe,
/// as in the shaders (`ALPHA_DELTA` in bsdf.glsl).
pub const ALPHA_DELTA: f32 = 1e-3;

impl Material {
    /// True for the perfect specular surfaces that caustic rays pass:
    /// mirrors, smooth conductors and smooth dielectrics.
    pub fn is_specular(&self) -> bool {
        match self.kind {
            MaterialKind::Mirror => true,
            MaterialKind::Conductor { roughness, .. } | MaterialKind::Dielectric { roughness, .. } => {
                roughness * roughness < ALPHA_DELTA
            }
            MaterialKind::Diffuse => false,
        }
    }
}

impl Light {
    /// True for the lights that emit caustic rays: point, sphere and
    /// directional lights (rect lights' caustics are left to the path tracer).
    pub fn emits_caustic_rays(&self) -> bool {
        !matches!(self, Light::Rect { .. })
    }

    /// True for the lights with a position (point, sphere, rect): those the
    /// volume pass and the equiangular estimates aim at (`positionalLight`
    /// in glsl/lib/light_queries.glsl).
    pub fn is_positional(&self) -> bool {
        !matches!(self, Light::Directional { .. })
    }
}

impl Scene {
    /// A copy of the scene to render at `width` x `height` with `spp`
    /// samples per pixel.
    pub fn resized(&self, width: u32, height: u32, spp: u32) -> Self {
        let mut s = self.clone();
        (s.image.width, s.image.height, s.image.spp) = (width, height, spp);
        s
    }

    /// The scene at frame `frame` of its camera animation (the camera
    /// interpolated, [`Camera::at_frame`]); a copy of it for a still camera.
    pub fn at_frame(&self, frame: u32) -> Self {
        let mut s = self.clone();
        s.camera = self.camera.at_frame(frame);
        s
    }

    /// True when some medium (the fog, or a dielectric's interior) has a
    /// positive density: the render shader's media code is compiled out
    /// otherwise.
    pub fn has_media(&self) -> bool {
        self.fog.iter().chain(self.materials.iter().filter_map(|m| m.medium.as_ref())).any(|m| m.density > 0.0)
    }

    /// True when some material has a texture map (an albedo, normal,
    /// roughness or displacement map): only then do the filtered modes take
    /// a share of the pixel filter into their footprints.
    pub fn has_texture_maps(&self) -> bool {
        self.materials.iter().any(|m| m.maps != MaterialMaps::default())
    }

    /// True when the volume pass has work: volume samples are enabled, and
    /// the scene has fog and a point, sphere or rect light.
    pub fn needs_volume(&self) -> bool {
        self.volume.samples > 0
            && self.fog.is_some_and(|f| f.density > 0.0)
            && self.lights.iter().any(Light::is_positional)
    }

    /// True when the caustic passes have work: caustic rays are enabled, and
    /// the scene has a light that emits them, a specular object and a diffuse
    /// receiver.
    pub fn needs_caustics(&self) -> bool {
        let has = |pred: &dyn Fn(&Material) -> bool| self.objects.iter().any(|o| pred(&self.materials[o.material]));
        self.caustics.rays > 0
            && self.lights.iter().any(Light::emits_caustic_rays)
            && has(&Material::is_specular)
            && has(&|m| matches!(m.kind, MaterialKind::Diffuse))
    }
}

/// A lat-long environment map: the radiance arriving from infinity, what
/// rays that hit nothing see, importance-sampled as a light
/// (`sampling::envmap` documents the mapping and the sampling).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct EnvironmentMapSettings {
    /// Index of the map in [`Scene::textures`] (level 0 is used).
    pub texture: usize,
    /// Radiance scale applied to the map.
    pub scale: f32,
}
