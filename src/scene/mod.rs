//! The scene a renderer consumes: camera, image settings, materials,
//! functional objects with transforms, and lights. `file.rs` reads it from
//! TOML (documented field by field in `scenes/README.md`).

pub mod file;

use glam::{DAffine3, DVec3, Vec3};

use crate::geometry::FunctionalObject;

pub use file::{load_scene, parse_scene, SceneError, DEFAULT_SCENE, DEFAULT_SCENE_NAME};

/// A pinhole camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position in world space.
    pub position: DVec3,
    /// The point the camera looks at.
    pub look_at: DVec3,
    /// Up direction (need not be orthogonal to the view direction).
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub vfov_degrees: f64,
}

/// Image size, sampling and exposure.
#[derive(Clone, Debug, PartialEq)]
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
}

/// How a surface scatters light.
#[derive(Clone, Debug, PartialEq)]
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
#[derive(Clone, Copy, Debug, PartialEq)]
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
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name used by objects to refer to it.
    pub name: String,
    /// Scattering model.
    pub kind: MaterialKind,
    /// Diffuse reflectance (diffuse) or reflectance (mirror); linear RGB, each in [0, 1].
    pub albedo: Vec3,
    /// Emitted radiance (linear RGB).
    pub emission: Vec3,
}

impl Material {
    /// A Lambertian material.
    pub fn diffuse(name: &str, albedo: Vec3) -> Self {
        Self { name: name.into(), kind: MaterialKind::Diffuse, albedo, emission: Vec3::ZERO }
    }
}

/// A functional object placed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneObject {
    /// Name, for messages.
    pub name: String,
    /// The surface in its own frame.
    pub shape: FunctionalObject,
    /// Object-to-world transform.
    pub transform: DAffine3,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// A light source.
#[derive(Clone, Debug, PartialEq)]
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
#[derive(Clone, Debug, PartialEq)]
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
}
