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
}

/// A Lambertian material, possibly emissive.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name used by objects to refer to it.
    pub name: String,
    /// Diffuse reflectance (linear RGB, each in [0, 1]).
    pub albedo: Vec3,
    /// Emitted radiance (linear RGB).
    pub emission: Vec3,
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
}

/// A whole scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Image settings.
    pub image: ImageSettings,
    /// Camera.
    pub camera: Camera,
    /// Radiance of rays that hit nothing (linear RGB).
    pub background: Vec3,
    /// Materials.
    pub materials: Vec<Material>,
    /// Objects.
    pub objects: Vec<SceneObject>,
    /// Lights.
    pub lights: Vec<Light>,
}
