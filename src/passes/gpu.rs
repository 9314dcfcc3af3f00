//! Host mirrors of the shader structs in `glsl/interface.glsl` and the other
//! shaders (scalar layout); `host_layouts` lists their members, which
//! `tests/scene/interface.rs` checks one by one against the SPIR-V.

use bytemuck::{Pod, Zeroable};

use glam::{DAffine3, DVec3};

use crate::geometry::{Perturbation, Quadric};
use crate::host_layout;
use crate::scene::{ConductorFresnel, Light, Material, MaterialKind, SceneObject, UvMapping};
use crate::shader_interface::{
    FRESNEL_COMPLEX, FRESNEL_SCHLICK, LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_RECT, LIGHT_SPHERE, MATERIAL_CONDUCTOR,
    MATERIAL_DIELECTRIC, MATERIAL_DIFFUSE, MATERIAL_MIRROR, NO_TEXTURE, UV_CYLINDRICAL, UV_PLANAR, UV_SPHERICAL,
};
use crate::vk::reflect::HostLayout;

/// `Quadric` in interface.glsl: A's six entries, b, c.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuQuadric {
    /// Axx, Ayy, Azz, Axy, Ayz, Axz.
    pub a: [f32; 6],
    /// Linear part.
    pub b: [f32; 3],
    /// Constant.
    pub c: f32,
}

impl From<&Quadric> for GpuQuadric {
    fn from(q: &Quadric) -> Self {
        let a = &q.a;
        Self {
            a: [a.x_axis.x, a.y_axis.y, a.z_axis.z, a.y_axis.x, a.z_axis.y, a.z_axis.x].map(|v| v as f32),
            b: q.b.to_array().map(|v| v as f32),
            c: q.c as f32,
        }
    }
}

/// `Object` in interface.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuObject {
    /// Base quadric in the object frame.
    pub base: GpuQuadric,
    /// Material index.
    pub material: u32,
    /// Index of the object's first cell in the cell table.
    pub first_cell: u32,
    /// `UV_*`.
    pub uv_mapping: u32,
    /// Planar mapping: gradient of u (object frame).
    pub u_axis: [f32; 3],
    /// Planar mapping: gradient of v.
    pub v_axis: [f32; 3],
    /// UV scale.
    pub uv_scale: [f32; 2],
    /// UV offset.
    pub uv_offset: [f32; 2],
    /// Object-frame distance of a ray's origin beyond which the ray is formed
    /// in f64 and searched in a parameter local to each cell
    /// ([`GpuObject::rebase_distance`]).
    pub rebase_distance: f32,
    /// The map from the GPU's world frame to the object's in f64, column
    /// major (x, y, z, translation).
    pub world_to_object: [f64; 12],
}

/// Object-frame distance (in object units, and in sizes of the object's box)
/// beyond which rays are re-based (`glsl/root_search.glsl`): there an f32
/// ray parameter resolves 6e-8 · 64 = 4e-6 of the distance.
pub const REBASE_DISTANCE: f64 = 64.0;

impl GpuObject {
    /// The object's base quadric, material and texture coordinates, and its
    /// placement: `to_world` maps its frame to the GPU's world frame (the
    /// scene's, relative to the frame's origin).
    pub fn new(object: &SceneObject, first_cell: u32, to_world: &DAffine3) -> Self {
        let (uv_mapping, u_axis, v_axis) = match object.uv.mapping {
            UvMapping::Planar { u_axis, v_axis } => (UV_PLANAR, u_axis, v_axis),
            UvMapping::Spherical => (UV_SPHERICAL, DVec3::X, DVec3::Z),
            UvMapping::Cylindrical => (UV_CYLINDRICAL, DVec3::X, DVec3::Z),
        };
        Self {
            base: GpuQuadric::from(&object.shape.base),
            material: object.material as u32,
            first_cell,
            uv_mapping,
            u_axis: u_axis.as_vec3().to_array(),
            v_axis: v_axis.as_vec3().to_array(),
            uv_scale: object.uv.scale.as_vec2().to_array(),
            uv_offset: object.uv.offset.as_vec2().to_array(),
            rebase_distance: Self::rebase_distance(object) as f32,
            world_to_object: to_world.inverse().to_cols_array(),
        }
    }

    /// [`REBASE_DISTANCE`] object units, or that many half-diagonals of the
    /// object's box where the object is smaller than a unit: what f32 can
    /// resolve is relative to the distance, so a small object needs the f64
    /// path nearer.
    pub fn rebase_distance(object: &SceneObject) -> f64 {
        let size = object.shape.bounds().map_or(1.0, |b| 0.5 * b.size().length());
        REBASE_DISTANCE * size.min(1.0)
    }
}

/// `Perturbation` in interface.glsl (48 bytes): a bounded support stored
/// about its centre, where the quadric has no linear term; an unbounded one
/// in the object frame, its linear term where the centre would be.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuPerturbation {
    /// Axx, Ayy, Azz, Axy, Ayz, Axz of the perturbing quadric.
    pub a: [f32; 6],
    /// Its constant: Q(p) = hᵀAh + c about the centre (bounded), or
    /// pᵀAp + b·p + c (unbounded).
    pub c: f32,
    /// Form factor.
    pub f: f32,
    /// Bounded support: the centre of the sphere bounding {Q >= 0} (object
    /// frame). Unbounded: the linear part b.
    pub centre_or_linear: [f32; 3],
    /// Radius of that sphere; negative when the support is unbounded.
    pub radius: f32,
}

/// A bounded support's quadric about its centre keeps a linear term of
/// rounding size only (the centre solves ∇Q = 0 in f64), dropped on the GPU
/// while it is below this share of the quadric's other terms over the
/// support (f32 resolves 6e-8 of them). A support so ill-conditioned that
/// its term is larger is stored as an unbounded one (exact, without the
/// bounding-sphere test).
const DROPPED_LINEAR_TERM: f64 = 1e-9;

impl From<&Perturbation> for GpuPerturbation {
    fn from(p: &Perturbation) -> Self {
        let about_centre = p.quadric.support_sphere().and_then(|(centre, radius)| {
            let local = p.quadric.transformed(&DAffine3::from_translation(-centre));
            let quadratic = local.a.to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs())) * radius * radius;
            let negligible = local.b.length() * radius <= DROPPED_LINEAR_TERM * quadratic.max(local.c.abs());
            negligible.then_some((centre, local, radius as f32))
        });
        let (centre_or_linear, q, radius) = match about_centre {
            Some((centre, local, radius)) => (centre, GpuQuadric::from(&local), radius),
            None => (p.quadric.b, GpuQuadric::from(&p.quadric), -1.0),
        };
        Self {
            a: q.a,
            c: q.c,
            f: p.form_factor as f32,
            centre_or_linear: centre_or_linear.as_vec3().to_array(),
            radius,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bounded support goes up about its centre with no linear term, an
    /// unbounded one with its linear term in place of the centre; both give
    /// the quadric's values (f32).
    #[test]
    fn perturbations_keep_their_quadric_in_48_bytes() {
        assert_eq!(std::mem::size_of::<GpuPerturbation>(), 48);
        let ellipsoid = Quadric::ellipsoid(DVec3::new(0.3, -0.2, 0.9), DVec3::new(0.05, 0.08, 0.03));
        let turned = ellipsoid.transformed(&DAffine3::from_rotation_y(0.7));
        let plane = Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -2.0, 0.5, 0.25]);
        for (q, bounded) in [(ellipsoid, true), (turned, true), (plane, false)] {
            let g = GpuPerturbation::from(&Perturbation { quadric: q, form_factor: 0.5 });
            assert_eq!(g.radius >= 0.0, bounded);
            let centre = if bounded { DVec3::from(g.centre_or_linear.map(f64::from)) } else { DVec3::ZERO };
            let b = if bounded { DVec3::ZERO } else { DVec3::from(g.centre_or_linear.map(f64::from)) };
            let [xx, yy, zz, xy, yz, xz] = g.a.map(f64::from);
            for p in [DVec3::new(0.3, -0.2, 0.9), DVec3::new(0.33, -0.15, 0.88), DVec3::new(-1.0, 0.5, 2.0)] {
                let h = p - centre;
                let gpu = xx * h.x * h.x
                    + yy * h.y * h.y
                    + zz * h.z * h.z
                    + 2.0 * (xy * h.x * h.y + yz * h.y * h.z + xz * h.x * h.z)
                    + b.dot(h)
                    + f64::from(g.c);
                let exact = q.eval(p);
                // f32 coefficients: within a few roundings of the terms' size.
                let size = q.a.abs().mul_vec3(h.abs()).dot(h.abs()) + b.abs().dot(h.abs()) + f64::from(g.c).abs();
                assert!((gpu - exact).abs() <= 1e-6 * size, "{q:?} at {p}: {gpu} against {exact}");
            }
        }
    }
}

/// `Cell` in interface.glsl: one procedural AABB.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuCell {
    /// Box minimum (object frame).
    pub lo: [f32; 3],
    /// Box maximum.
    pub hi: [f32; 3],
    /// First entry in the cell lists.
    pub first: u32,
    /// Number of perturbations.
    pub count: u32,
}

/// `Material` in bsdf.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuMaterial {
    /// `MATERIAL_*`.
    pub kind: u32,
    /// Diffuse albedo or mirror reflectance.
    pub albedo: [f32; 3],
    /// Emitted radiance.
    pub emission: [f32; 3],
    /// Perceptual roughness (GGX α = roughness²).
    pub roughness: f32,
    /// Dielectric index of refraction (inside / outside).
    pub ior: f32,
    /// `FRESNEL_*` (conductors).
    pub fresnel: u32,
    /// Conductor η per RGB, or Schlick's f0.
    pub eta: [f32; 3],
    /// Conductor κ per RGB.
    pub k: [f32; 3],
    /// Texture index of the colour map, or `NO_TEXTURE`.
    pub albedo_map: u32,
    /// Texture index of the normal map, or `NO_TEXTURE`.
    pub normal_map: u32,
    /// Texture index of the roughness map, or `NO_TEXTURE`.
    pub roughness_map: u32,
    /// Texture index of the displacement map, or `NO_TEXTURE`.
    pub displacement_map: u32,
    /// Height of a displacement value of 1, in object units.
    pub displacement_scale: f32,
    /// Texture index of the normal map's slope moments
    /// (`texture::lean::normal_slope_moments`), or `NO_TEXTURE`.
    pub normal_moments: u32,
    /// Texture index of the displacement map's slope moments
    /// (`texture::lean::height_slope_moments`), or `NO_TEXTURE`.
    pub displacement_moments: u32,
    /// The medium inside (dielectrics; density 0: clear).
    pub medium: GpuMedium,
}

/// `Medium` in media.glsl: a homogeneous medium (density 0: none).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuMedium {
    /// Extinction σ_t per unit length.
    pub density: f32,
    /// Single-scattering albedo per RGB channel.
    pub albedo: [f32; 3],
    /// Henyey–Greenstein g.
    pub anisotropy: f32,
}

impl From<Option<&crate::scene::Medium>> for GpuMedium {
    fn from(m: Option<&crate::scene::Medium>) -> Self {
        m.map_or_else(Self::default, |m| Self {
            density: m.density,
            albedo: m.albedo.to_array(),
            anisotropy: m.anisotropy,
        })
    }
}

impl From<&Material> for GpuMaterial {
    fn from(m: &Material) -> Self {
        let mut g = GpuMaterial {
            albedo: m.albedo.to_array(),
            emission: m.emission.to_array(),
            ior: 1.0,
            albedo_map: m.maps.albedo.map_or(NO_TEXTURE, |i| i as u32),
            normal_map: m.maps.normal.map_or(NO_TEXTURE, |i| i as u32),
            roughness_map: m.maps.roughness.map_or(NO_TEXTURE, |i| i as u32),
            displacement_map: m.maps.displacement.map_or(NO_TEXTURE, |(i, _)| i as u32),
            displacement_scale: m.maps.displacement.map_or(0.0, |(_, s)| s),
            normal_moments: NO_TEXTURE,
            displacement_moments: NO_TEXTURE,
            medium: GpuMedium::from(m.medium.as_ref()),
            ..Default::default()
        };
        match &m.kind {
            MaterialKind::Diffuse => g.kind = MATERIAL_DIFFUSE,
            MaterialKind::Mirror => g.kind = MATERIAL_MIRROR,
            MaterialKind::Dielectric { roughness, ior } => {
                g.kind = MATERIAL_DIELECTRIC;
                g.roughness = *roughness;
                g.ior = *ior;
            }
            MaterialKind::Conductor { roughness, fresnel } => {
                g.kind = MATERIAL_CONDUCTOR;
                g.roughness = *roughness;
                match fresnel {
                    ConductorFresnel::Complex { eta, k } => {
                        g.fresnel = FRESNEL_COMPLEX;
                        g.eta = eta.to_array();
                        g.k = k.to_array();
                    }
                    ConductorFresnel::Schlick { f0 } => {
                        g.fresnel = FRESNEL_SCHLICK;
                        g.eta = f0.to_array();
                    }
                }
            }
        }
        g
    }
}

/// `Light` in lights.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLight {
    /// `LIGHT_*`.
    pub kind: u32,
    /// Point position, sphere centre, rect corner, or the unit direction
    /// toward a directional light.
    pub position: [f32; 3],
    /// Radius (sphere lights).
    pub radius: f32,
    /// Intensity (point), radiance (sphere, rect) or irradiance (directional).
    pub color: [f32; 3],
    /// First edge (rect).
    pub edge_u: [f32; 3],
    /// Second edge (rect); the light emits toward edge_u × edge_v.
    pub edge_v: [f32; 3],
}

impl GpuLight {
    /// The light with its position relative to `origin` (subtracted in f64,
    /// before the rounding to f32; directional lights have none).
    pub fn relative_to(l: &Light, origin: DVec3) -> Self {
        let mut l = l.clone();
        match &mut l {
            Light::Point { position: p, .. } | Light::Sphere { centre: p, .. } | Light::Rect { corner: p, .. } => {
                *p -= origin
            }
            Light::Directional { .. } => {}
        }
        Self::from(&l)
    }
}

impl From<&Light> for GpuLight {
    fn from(l: &Light) -> Self {
        let f = |v: DVec3| v.as_vec3().to_array();
        match l {
            Light::Point { position, intensity } => GpuLight {
                kind: LIGHT_POINT,
                position: f(*position),
                color: intensity.to_array(),
                ..Default::default()
            },
            Light::Sphere { centre, radius, radiance } => GpuLight {
                kind: LIGHT_SPHERE,
                position: f(*centre),
                radius: *radius as f32,
                color: radiance.to_array(),
                ..Default::default()
            },
            Light::Rect { corner, edge_u, edge_v, radiance } => GpuLight {
                kind: LIGHT_RECT,
                position: f(*corner),
                color: radiance.to_array(),
                edge_u: f(*edge_u),
                edge_v: f(*edge_v),
                ..Default::default()
            },
            Light::Directional { direction, irradiance } => GpuLight {
                kind: LIGHT_DIRECTIONAL,
                position: f(direction.normalize()),
                color: irradiance.to_array(),
                ..Default::default()
            },
        }
    }
}

/// `Frame` in render.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuFrame {
    /// Camera position.
    pub eye: [f32; 3],
    /// View direction (unit).
    pub forward: [f32; 3],
    /// Right vector scaled by tan(fov/2) · aspect.
    pub right: [f32; 3],
    /// Up vector scaled by tan(fov/2).
    pub up: [f32; 3],
    /// Background radiance.
    pub background: [f32; 3],
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Random seed.
    pub seed: u32,
    /// Number of lights.
    pub light_count: u32,
    /// Longest path in bounces.
    pub max_depth: u32,
    /// Texture index of the environment map, or `NO_TEXTURE`.
    pub env_map: u32,
    /// Environment map width.
    pub env_width: u32,
    /// Environment map height.
    pub env_height: u32,
    /// Environment map radiance scale.
    pub env_scale: f32,
    /// The medium outside the objects (fog; density 0: none).
    pub fog: GpuMedium,
    /// The Gaussian pixel filter's σ in pixels ([`PIXEL_FILTER_SIGMA`](crate::passes::render::PIXEL_FILTER_SIGMA)).
    pub pixel_sigma: f32,
    /// The share of the pixel filter's variance that the filtered modes'
    /// footprints carry ([`footprint_fraction`](crate::passes::render::footprint_fraction)).
    pub footprint_fraction: f32,
}

/// `Aov` in render.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuAov {
    /// Distance along the normalised pixel-centre ray (infinity on a miss).
    pub depth: f32,
    /// World-space outward normal (zero on a miss).
    pub normal: [f32; 3],
    /// Material albedo (zero on a miss).
    pub albedo: [f32; 3],
    /// Index of the object hit (`NO_HIT` on a miss).
    pub object: u32,
}

/// `PathVertex` in render.comp: one event of a recorded path (the outlier
/// report's). The fields' meanings depend on `event` (an `EVENT_*`
/// constant); render.comp documents each.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuPathVertex {
    /// `EVENT_*`.
    pub event: u32,
    /// Object index, or the light index for emitters and light samples
    /// (`NO_HIT`: the environment or none).
    pub object: u32,
    /// Material index (`NO_TEXTURE` when none).
    pub material: u32,
    /// `LOBE_*` for surface events, the light kind for emitters and light
    /// samples, 1/0 for shadow rays (unblocked/blocked), 1 for a non-finite
    /// end.
    pub lobe: u32,
    /// Ray parameter of the hit, or the shadow ray's or light's distance.
    pub t: f32,
    /// Cosine of wo with the shading normal (signed).
    pub cos_o: f32,
    /// Cosine of wi with the shading normal (signed).
    pub cos_i: f32,
    /// Solid-angle pdf of the sample (0: delta lobe), the MIS weight for
    /// emitters, the survival probability for Russian roulette.
    pub pdf: f32,
    /// Where (in the GPU frame, relative to the camera).
    pub position: [f32; 3],
    /// The sample's weight, or the contribution an emitter or shadow ray brings.
    pub weight: [f32; 3],
    /// The path throughput after the event (0 for light samples and shadow
    /// rays: what they bring includes the throughput of their vertex).
    pub throughput: [f32; 3],
    /// The sample's radiance so far.
    pub radiance: [f32; 3],
}

/// `Ray` in probe.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuRay {
    /// Origin.
    pub origin: [f32; 3],
    /// Parameter range start.
    pub tmin: f32,
    /// Direction.
    pub dir: [f32; 3],
    /// Parameter range end.
    pub tmax: f32,
}

/// `Hit` in probe.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuHit {
    /// Ray parameter of the closest hit (3.4e38 on a miss).
    pub t: f32,
    /// World-space outward unit normal.
    pub normal: [f32; 3],
    /// Object index, or `NO_HIT`.
    pub object: u32,
    /// Mean curvature of the outward normal (positive when convex), 1/length.
    pub mean_curvature: f32,
    /// Gaussian curvature, 1/length².
    pub gauss_curvature: f32,
    /// The hit in the object's frame.
    pub object_point: [f32; 3],
}

/// Push constants of render.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct RenderPush {
    /// First pixel of the tile.
    pub tile_origin: [u32; 2],
    /// Tile size in pixels.
    pub tile_size: [u32; 2],
    /// Sample number (seeds the random sequence).
    pub sample_index: u32,
    /// 1 to write the AOVs in this dispatch.
    pub write_aov: u32,
}

/// One filtered texture lookup for texprobe.comp: a footprint (centre and
/// 1σ semi-axes in (u, v)) and a GGX α to widen by the looked-up slope
/// moments.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuTexQuery {
    /// Texture index.
    pub texture: u32,
    /// GGX α before widening.
    pub alpha: f32,
    /// Footprint centre.
    pub uv: [f32; 2],
    /// First semi-axis.
    pub axis1: [f32; 2],
    /// Second semi-axis.
    pub axis2: [f32; 2],
}

/// The result of a [`GpuTexQuery`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuTexResult {
    /// The EWA-filtered texel value.
    pub value: [f32; 4],
    /// `leanAlpha(alpha, value)`: α widened by the slope variance of `value`
    /// read as slope moments.
    pub alpha: f32,
    /// Padding.
    pub pad: [u32; 3],
}

/// Push constants of probe.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ProbePush {
    /// First ray of the dispatch.
    pub first: u32,
    /// Number of rays.
    pub count: u32,
}

/// `CausticRay` in caustics.glsl: where a caustic ray landed.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuCausticRay {
    /// Landing point (GPU frame).
    pub position: [f32; 3],
    /// Object landed on (`NO_HIT` for an invalid ray).
    pub object: u32,
    /// Flux carried when landing (W, RGB).
    pub flux: [f32; 3],
    /// Identifier of the sequence of surfaces; 0 marks an invalid ray.
    pub path: u32,
    /// Start of the ray's last segment (its last specular vertex).
    pub beam_start: [f32; 3],
    /// 1 when the last segment runs through the fog.
    pub in_fog: u32,
}

/// `Receiver` in caustics.glsl: the first surface through a pixel's centre.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuReceiver {
    /// Hit point (GPU frame).
    pub position: [f32; 3],
    /// Object hit, or `NO_HIT`.
    pub object: u32,
}

/// `Emitter` in caustics.glsl: one grid of caustic rays (push constants of
/// the caustic passes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuEmitter {
    /// Point emitters: the light's position; parallel: the grid plane's centre.
    pub origin: [f32; 3],
    /// `EMITTER_POINT` or `EMITTER_PARALLEL`.
    pub kind: u32,
    /// Grid plane axis (unit).
    pub u: [f32; 3],
    /// Index of the grid's first ray in the ray buffer.
    pub first_ray: u32,
    /// Grid plane axis (unit).
    pub v: [f32; 3],
    /// Specular vertices a ray may pass before it lands.
    pub max_specular: u32,
    /// Emission axis (unit): toward the grid plane at distance 1 (point), or
    /// the rays' direction (parallel).
    pub w: [f32; 3],
    /// Padding.
    pub pad: f32,
    /// Lower corner of the grid rectangle in (u, v).
    pub lo: [f32; 2],
    /// Upper corner of the grid rectangle in (u, v).
    pub hi: [f32; 2],
    /// Rays along u and along v.
    pub grid: [u32; 2],
    /// Intensity (W/sr, point) or irradiance (W/m², parallel), RGB.
    pub power: [f32; 3],
}

/// `Push` in volume.comp: one batch of the volume pass's samples.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct VolumePush {
    /// The batch's first sample.
    pub first_sample: u32,
    /// Samples in the batch.
    pub samples: u32,
    /// Samples per pixel in all.
    pub total: u32,
}

/// `PathRecord` in render.comp: the events of one pixel's recorded path.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GpuPathRecord {
    /// Events of the path (more than the vertices kept when it is long).
    pub count: u32,
    /// The first events.
    pub vertices: [GpuPathVertex; crate::shader_interface::PATH_RECORD_VERTICES as usize],
}

/// `LoopBudget` in loop_budget.glsl: the loop iterations the tracing
/// invocations counted ([`crate::passes::LoopBudget`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLoopBudget {
    /// The most loop iterations one invocation counted.
    pub most_edges: u32,
    /// Invocations that reported.
    pub invocations: u32,
    /// loop_budget.comp: how far its uncounted loop ran.
    pub spent: u32,
    /// Padding.
    pub pad: u32,
}

/// `Push` in loop_budget.comp: the loop iterations to spend.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LoopBudgetPush {
    /// Loop iterations to spend.
    pub spend: u32,
}

/// `Push` in the caustic shaders: the grid being traced.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct CausticPush {
    /// The grid.
    pub emitter: GpuEmitter,
}

/// Every struct the host shares with the shaders, for the member-by-member
/// check against their SPIR-V (`tests/scene/interface.rs`): names (GLSL
/// `camelCase` as Rust `snake_case`), order, offsets, sizes. This replaces
/// checks by size, which a swap of two fields of one type passes.
pub fn host_layouts() -> Vec<HostLayout> {
    vec![
        host_layout!(GpuQuadric as "Quadric" { a, b, c }),
        host_layout!(GpuObject as "Object" {
            base, material, first_cell, uv_mapping, u_axis, v_axis, uv_scale, uv_offset, rebase_distance, world_to_object
        }),
        host_layout!(GpuPerturbation as "Perturbation" { a, c, f, centre_or_linear, radius }),
        host_layout!(GpuCell as "Cell" { lo, hi, first, count }),
        host_layout!(GpuMaterial as "Material" {
            kind, albedo, emission, roughness, ior, fresnel, eta, k, albedo_map, normal_map, roughness_map,
            displacement_map, displacement_scale, normal_moments, displacement_moments, medium
        }),
        host_layout!(GpuMedium as "Medium" { density, albedo, anisotropy }),
        host_layout!(GpuLight as "Light" { kind, position, radius, color, edge_u, edge_v }),
        host_layout!(GpuFrame as "Frame" {
            eye, forward, right, up, background, width, height, seed, light_count, max_depth, env_map, env_width,
            env_height, env_scale, fog, pixel_sigma, footprint_fraction
        }),
        host_layout!(GpuAov as "Aov" { depth, normal, albedo, object }),
        host_layout!(GpuPathVertex as "PathVertex" {
            event, object, material, lobe, t, cos_o, cos_i, pdf, position, weight, throughput, radiance
        }),
        host_layout!(GpuPathRecord as "PathRecord" { count, vertices }),
        host_layout!(GpuRay as "Ray" { origin, tmin, dir, tmax }),
        host_layout!(GpuHit as "Hit" { t, normal, object, mean_curvature, gauss_curvature, object_point }),
        host_layout!(GpuTexQuery as "TexQuery" { texture, alpha, uv, axis1, axis2 }),
        host_layout!(GpuTexResult as "TexResult" { value, alpha, pad }),
        host_layout!(GpuCausticRay as "CausticRay" { position, object, flux, path, beam_start, in_fog }),
        host_layout!(GpuReceiver as "Receiver" { position, object }),
        host_layout!(GpuEmitter as "Emitter" { origin, kind, u, first_ray, v, max_specular, w, pad, lo, hi, grid, power }),
        host_layout!(GpuLoopBudget as "LoopBudget" { most_edges, invocations, spent, pad }),
        host_layout!(LoopBudgetPush as "Push" in ["loop_budget"] { spend }),
        host_layout!(RenderPush as "Push" in ["render"] { tile_origin, tile_size, sample_index, write_aov }),
        host_layout!(ProbePush as "Push" in ["probe", "texprobe"] { first, count }),
        host_layout!(VolumePush as "Push" in ["volume"] { first_sample, samples, total }),
        host_layout!(CausticPush as "Push" in ["caustic_trace", "caustic_splat", "caustic_beams"] { emitter }),
    ]
}
