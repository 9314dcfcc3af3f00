//! The raw schema: the TOML tables as serde reads them (`Raw*`), before the
//! checks that involve more than one value.

use glam::Vec3;
use serde::Deserialize;
use toml::Spanned;

use super::Medium;
use crate::model::texture::MAX_TEXTURE_SIZE;

use super::*;

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scene table")]
pub(super) struct RawScene {
    pub(super) background: Option<Spanned<Triple<NonNegative>>>,
    pub(super) environment: Option<Spanned<RawEnvironment>>,
    pub(super) fog: Option<Spanned<RawMedium>>,
    pub(super) caustics: Option<RawCaustics>,
    pub(super) volume: Option<RawVolume>,
    pub(super) image: Option<RawImage>,
    pub(super) camera: Spanned<RawCamera>,
    #[serde(default)]
    pub(super) materials: Vec<Spanned<RawMaterial>>,
    #[serde(default)]
    pub(super) objects: Vec<Spanned<RawObject>>,
    #[serde(default)]
    pub(super) lights: Vec<Spanned<RawLight>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [image] table")]
pub(super) struct RawImage {
    pub(super) width: Option<Dimension>,
    pub(super) height: Option<Dimension>,
    pub(super) spp: Option<Samples>,
    pub(super) seed: Option<Seed>,
    pub(super) exposure: Option<Exposure>,
    pub(super) max_depth: Option<Depth>,
    pub(super) preset: Option<Spanned<String>>,
    pub(super) filter: Option<Spanned<String>>,
    pub(super) denoise: Option<bool>,
    pub(super) denoise_quality: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [volume] table")]
pub(super) struct RawVolume {
    pub(super) samples: Option<VolumeSamples>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [caustics] table")]
pub(super) struct RawCaustics {
    pub(super) rays: Option<CausticRays>,
    pub(super) light_samples: Option<LightSamples>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a medium table such as { density = 0.2, albedo = [0.9, 0.9, 0.9], anisotropy = 0.3 }"
)]
pub(super) struct RawMedium {
    pub(super) density: NonNegative,
    pub(super) albedo: Option<Triple<UnitInterval>>,
    pub(super) anisotropy: Option<Anisotropy>,
}

impl RawMedium {
    /// The medium; the albedo defaults to 1 (no absorption), the anisotropy to 0.
    pub(super) fn build(&self) -> Medium {
        Medium {
            density: self.density.get() as f32,
            albedo: self.albedo.map_or(Vec3::ONE, |a| a.get().as_vec3()),
            anisotropy: self.anisotropy.map_or(0.0, |g| g.get() as f32),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [environment] table with a map")]
pub(super) struct RawEnvironment {
    pub(super) map: Spanned<RawMap<RawEnvironmentMapTable>>,
    pub(super) scale: Option<NonNegative>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "an environment map table such as { file = \"sky.exr\" } or { sky = { width = 512, height = 256 } }"
)]
pub(super) struct RawEnvironmentMapTable {
    pub(super) file: Option<Spanned<String>>,
    pub(super) sky: Option<Spanned<RawSky>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { width = 512, height = 256 }")]
pub(super) struct RawSky {
    pub(super) width: SkyWidth,
    pub(super) height: SkyHeight,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [camera] table with position and look_at")]
pub(super) struct RawCamera {
    pub(super) position: Triple<Finite>,
    pub(super) look_at: Spanned<Triple<Finite>>,
    pub(super) up: Option<Spanned<Triple<Finite>>>,
    pub(super) fov: Option<Fov>,
    pub(super) fps: Option<Positive>,
    pub(super) keyframes: Option<Vec<Spanned<RawKeyframe>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [[camera.keyframes]] table with time, position and look_at")]
pub(super) struct RawKeyframe {
    pub(super) time: Finite,
    pub(super) position: Triple<Finite>,
    pub(super) look_at: Spanned<Triple<Finite>>,
    pub(super) up: Option<Spanned<Triple<Finite>>>,
    pub(super) fov: Option<Fov>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Debug, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum MaterialType {
    Diffuse,
    Conductor,
    Dielectric,
    Mirror,
}

impl MaterialType {
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Diffuse => "diffuse",
            Self::Conductor => "conductor",
            Self::Dielectric => "dielectric",
            Self::Mirror => "mirror",
        }
    }
}

/// The keys each material type accepts, in the order messages list them.
pub(super) const MATERIAL_KEYS: [(&str, &[&str]); 4] = [
    ("diffuse", &["name", "type", "albedo", "emission", "albedo_map", "normal_map", "displacement_map"]),
    (
        "conductor",
        &[
            "name",
            "type",
            "roughness",
            "color",
            "eta",
            "k",
            "metal",
            "emission",
            "roughness_map",
            "normal_map",
            "displacement_map",
        ],
    ),
    (
        "dielectric",
        &["name", "type", "ior", "roughness", "emission", "roughness_map", "normal_map", "displacement_map", "medium"],
    ),
    ("mirror", &["name", "type", "albedo", "emission", "albedo_map", "normal_map", "displacement_map"]),
];

/// A named conductor whose complex index of refraction is built in.
#[derive(Deserialize, Clone, Copy, PartialEq, Debug, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum Metal {
    Gold,
    Silver,
    Copper,
    #[serde(alias = "aluminum")]
    Aluminium,
}

impl Metal {
    /// The complex index of refraction η + iκ at 650, 550 and 450 nm (red,
    /// green, blue), linearly interpolated between neighbouring rows of the
    /// measured tables as published by refractiveindex.info (CC0):
    ///
    /// * gold, silver, copper: P. B. Johnson and R. W. Christy, "Optical
    ///   constants of the noble metals", Phys. Rev. B 6, 4370 (1972);
    /// * aluminium: A. D. Rakić, "Algorithm for the determination of intrinsic
    ///   optical constants of metal films: application to aluminum", Appl.
    ///   Opt. 34, 4755 (1995).
    ///
    /// These are physical constants; their normal-incidence reflectances
    /// ((η−1)² + κ²) / ((η+1)² + κ²) are about gold (0.96, 0.79, 0.41),
    /// silver (0.99, 0.98, 0.98), copper (0.94, 0.62, 0.54) and aluminium
    /// (0.91, 0.92, 0.92).
    pub(super) fn ior(self) -> (Vec3, Vec3) {
        let (eta, k) = match self {
            Self::Gold => ([0.156, 0.424, 1.383], [3.602, 2.472, 1.915]),
            Self::Silver => ([0.052, 0.060, 0.040], [4.409, 3.597, 2.648]),
            Self::Copper => ([0.238, 1.007, 1.240], [3.626, 2.582, 2.393]),
            Self::Aluminium => ([1.558, 1.015, 0.633], [7.712, 6.627, 5.454]),
        };
        (Vec3::from_array(eta), Vec3::from_array(k))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a material table with a name")]
pub(super) struct RawMaterial {
    pub(super) name: Spanned<String>,
    #[serde(rename = "type")]
    pub(super) kind: Option<Spanned<MaterialType>>,
    pub(super) albedo: Option<Spanned<Triple<UnitInterval>>>,
    pub(super) emission: Option<Spanned<Triple<NonNegative>>>,
    pub(super) roughness: Option<Spanned<UnitInterval>>,
    pub(super) color: Option<Spanned<Triple<UnitInterval>>>,
    pub(super) eta: Option<Spanned<Triple<Ior>>>,
    pub(super) k: Option<Spanned<Triple<NonNegative>>>,
    pub(super) metal: Option<Spanned<Metal>>,
    pub(super) ior: Option<Spanned<Ior>>,
    pub(super) albedo_map: Option<Spanned<RawMap>>,
    pub(super) normal_map: Option<Spanned<RawMap>>,
    pub(super) roughness_map: Option<Spanned<RawMap>>,
    pub(super) displacement_map: Option<Spanned<RawMap>>,
    pub(super) medium: Option<Spanned<RawMedium>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a texture map table such as { file = \"wood.png\" }")]
pub(super) struct RawMapTable {
    pub(super) file: Option<Spanned<String>>,
    pub(super) checker: Option<Spanned<RawChecker>>,
    pub(super) bumps: Option<Spanned<RawBumps>>,
    pub(super) scale: Option<Spanned<Positive>>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table such as { size = 1024, cells = 64, colors = [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]] }"
)]
pub(super) struct RawChecker {
    pub(super) size: TextureSize,
    pub(super) cells: Spanned<Int<1, { MAX_TEXTURE_SIZE as i64 }>>,
    pub(super) colors: ColourPair,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { size = 512, count = 200, seed = 3, strength = 4 }")]
pub(super) struct RawBumps {
    pub(super) size: TextureSize,
    pub(super) count: Int<1, MAX_TEXTURE_BUMPS>,
    pub(super) seed: Option<Seed>,
    pub(super) strength: Option<Spanned<Positive>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an object table")]
pub(super) struct RawObject {
    pub(super) name: Option<String>,
    pub(super) material: Option<Spanned<String>>,
    pub(super) sphere: Option<Spanned<RawSphere>>,
    pub(super) ellipsoid: Option<Spanned<RawEllipsoid>>,
    pub(super) plane: Option<Spanned<RawPlane>>,
    pub(super) cylinder: Option<Spanned<RawCylinder>>,
    pub(super) cone: Option<Spanned<RawCone>>,
    pub(super) paraboloid: Option<Spanned<RawParaboloid>>,
    pub(super) hyperboloid: Option<Spanned<RawHyperboloid>>,
    pub(super) quadric: Option<Spanned<Coefficients>>,
    pub(super) clip: Option<Spanned<RawClip>>,
    pub(super) translate: Option<Triple<Finite>>,
    pub(super) rotate: Option<Triple<Finite>>,
    pub(super) scale: Option<PositiveVec>,
    #[serde(default)]
    pub(super) perturbations: Vec<Spanned<RawPerturbation>>,
    #[serde(default)]
    pub(super) scatter: Vec<Spanned<RawScatter>>,
    pub(super) uv: Option<Spanned<RawUv>>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Debug, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub(super) enum MappingName {
    Planar,
    Spherical,
    Cylindrical,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { mapping = \"spherical\", scale = [8, 4] }")]
pub(super) struct RawUv {
    pub(super) mapping: Option<MappingName>,
    pub(super) u_axis: Option<Spanned<Triple<Finite>>>,
    pub(super) v_axis: Option<Spanned<Triple<Finite>>>,
    pub(super) scale: Option<Pair<NonZero>>,
    pub(super) offset: Option<Pair<Finite>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radius = 1 }")]
pub(super) struct RawSphere {
    pub(super) radius: Positive,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radii = [1, 0.5, 2] }")]
pub(super) struct RawEllipsoid {
    pub(super) radii: Triple<Positive>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an empty table {}")]
pub(super) struct RawPlane {}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radius = 0.5 }")]
pub(super) struct RawCylinder {
    pub(super) radius: Positive,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { half_angle = 30 }")]
pub(super) struct RawCone {
    pub(super) half_angle: HalfAngle,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { curvature = 1 }")]
pub(super) struct RawParaboloid {
    pub(super) curvature: NonZero,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radius = 0.5, slope = 1, sheets = 1 }")]
pub(super) struct RawHyperboloid {
    pub(super) radius: Positive,
    pub(super) slope: Positive,
    pub(super) sheets: Option<Sheets>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { min = [-1, -1, -1], max = [1, 1, 1] }")]
pub(super) struct RawClip {
    pub(super) min: Triple<Finite>,
    pub(super) max: Triple<Finite>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a perturbation table with `f` and one of `bump` or `quadric`")]
pub(super) struct RawPerturbation {
    pub(super) bump: Option<RawBump>,
    pub(super) quadric: Option<Spanned<Coefficients>>,
    pub(super) f: Finite,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { centre = [0, 1, 0], radius = 0.2 }")]
pub(super) struct RawBump {
    #[serde(alias = "center")]
    pub(super) centre: Triple<Finite>,
    pub(super) radius: PositiveVec,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scatter table with count, radius and f")]
pub(super) struct RawScatter {
    pub(super) count: Count,
    pub(super) on_radii: Option<Triple<Positive>>,
    #[serde(alias = "center")]
    pub(super) centre: Option<Triple<Finite>>,
    pub(super) radius: PositiveVec,
    pub(super) f: Finite,
    pub(super) alternate: Option<bool>,
    pub(super) seed: Option<Seed>,
    pub(super) jitter: Option<UnitInterval>,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
pub(super) enum LightKind {
    Point,
    Sphere,
    Rect,
    Directional,
}

impl LightKind {
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Point => "point",
            Self::Sphere => "sphere",
            Self::Rect => "rect",
            Self::Directional => "directional",
        }
    }
}

/// The keys each light type accepts, in the order messages list them.
pub(super) const LIGHT_KEYS: [(&str, &[&str]); 4] = [
    ("point", &["type", "position", "intensity"]),
    ("sphere", &["type", "position", "radius", "radiance"]),
    ("rect", &["type", "corner", "edge_u", "edge_v", "radiance"]),
    ("directional", &["type", "direction", "irradiance"]),
];

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a light table with a type")]
pub(super) struct RawLight {
    #[serde(rename = "type")]
    pub(super) kind: LightKind,
    pub(super) position: Option<Spanned<Triple<Finite>>>,
    pub(super) intensity: Option<Spanned<Triple<NonNegative>>>,
    pub(super) radius: Option<Spanned<Positive>>,
    pub(super) radiance: Option<Spanned<Triple<NonNegative>>>,
    pub(super) corner: Option<Spanned<Triple<Finite>>>,
    pub(super) edge_u: Option<Spanned<Triple<Finite>>>,
    pub(super) edge_v: Option<Spanned<Triple<Finite>>>,
    pub(super) direction: Option<Spanned<Triple<Finite>>>,
    pub(super) irradiance: Option<Spanned<Triple<NonNegative>>>,
}

// ---------------------------------------------------------------------------
// Building the scene
// ---------------------------------------------------------------------------
