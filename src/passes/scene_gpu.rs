//! A scene on the GPU: object, cell and perturbation tables, one bottom-level
//! acceleration structure of procedural AABBs per object (one AABB per cell)
//! and a top level with each object's transform.

use std::sync::Arc;

use glam::{DAffine3, DMat3, DVec3};

use super::gpu::{GpuCell, GpuLight, GpuLoopBudget, GpuMaterial, GpuObject, GpuPerturbation};
use super::IntersectMode;
use super::RenderError;
use crate::gpu::shader_interface::{
    BINDING_CELLS, BINDING_CELL_LISTS, BINDING_FRAME, BINDING_LIGHTS, BINDING_LOOP_BUDGET, BINDING_MATERIALS,
    BINDING_OBJECTS, BINDING_PERTURBATIONS, BINDING_TEXTURES, BINDING_TLAS, MAX_TEXTURES, NO_TEXTURE, SPEC_FAR_RAYS,
    SPEC_LOOP_BUDGET,
};
use crate::model::geometry::{Aabb, CellParams};
use crate::model::sampling::envmap::EnvironmentMap;
use crate::model::scene::maps as scene_maps;
use crate::model::scene::{Light, Scene, TextureImage};
use crate::model::texture::encoding::{chain_texels, choose_encoding, MapContent, TexelEncoding};
use crate::vk::{vk, AccelerationStructure, Access, AsInstance, Binding, Buffer, Commands, Device, Image, Sampler};

/// Sizes of what a scene put on the GPU.
#[derive(Clone, Copy, Debug, Default)]
pub struct GeometryStats {
    /// Number of perturbations.
    pub perturbations: usize,
    /// Number of cells (procedural AABBs).
    pub cells: usize,
    /// Number of entries in the per-cell perturbation lists.
    pub cell_list_entries: usize,
    /// Bytes of the perturbation, cell and cell-list tables.
    pub table_bytes: u64,
    /// Bytes of the acceleration structures (bottom and top levels).
    pub accel_bytes: u64,
}

/// A scene uploaded to the GPU.
pub struct GpuScene {
    /// Top-level acceleration structure.
    pub tlas: AccelerationStructure,
    _blases: Vec<AccelerationStructure>,
    /// Object table.
    pub objects: Buffer,
    /// Cell table.
    pub cells: Buffer,
    /// Perturbation table.
    pub perturbations: Buffer,
    /// Per-cell perturbation lists.
    pub cell_lists: Buffer,
    /// Materials.
    pub materials: Buffer,
    /// Lights.
    pub lights: Buffer,
    /// Number of lights.
    pub light_count: u32,
    /// The scene's texture maps, then the slope moments derived from its
    /// normal and displacement maps, then a 1x1 white texture filling the
    /// remaining slots of the shader's texture array.
    pub textures: Vec<Image>,
    /// The sampler for every texture.
    pub sampler: Sampler,
    /// The environment map's sampling tables (`EnvironmentMap::cdf_buffer`;
    /// a placeholder when there is no map).
    pub env_cdf: Buffer,
    /// The environment map: (texture index, width, height, scale).
    pub environment: Option<(u32, u32, u32, f32)>,
    /// Sizes.
    pub stats: GeometryStats,
    /// The world point at the GPU frame's origin ([`Self::with_origin`]).
    pub origin: DVec3,
    /// The loop-budget report every tracing pass binds (`GpuLoopBudget`).
    loop_budget: Buffer,
    /// Whether passes built from now on measure the loop budget.
    measure_loop_budget: bool,
    /// Whether a ray can start beyond an object's rebase distance
    /// ([`Self::far_rays`]).
    far_rays: bool,
    /// How far from the frame's origin rays may start without the far-ray
    /// search ([`Self::near_reach`]).
    near_reach: f64,
}

/// Loop back-edges Mesa 25.0's gallivm source allows one shader invocation
/// (a vector of lanes) in all its loops before it silently leaves them
/// (`LP_MAX_TGSI_LOOP_ITERATIONS`; Mesa 25.1 removed the limit). The
/// loop-budget test measures whether the installed driver applies it.
pub const LOOP_LIMIT: u32 = 65_535;

/// The loop iterations the tracing invocations counted
/// (glsl/intersection/loop_budget.glsl) since [`GpuScene::reset_loop_budget`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopBudget {
    /// The most loop iterations one invocation counted.
    pub most_edges: u32,
    /// Invocations that reported.
    pub invocations: u32,
    /// loop_budget.comp only: how far its uncounted loop ran.
    pub spent: u32,
}

/// Host-visible memory a texture upload stages at most at once: larger maps
/// go up in pieces of whole rows.
const STAGING_BYTES: u64 = 64 << 20;

/// The Vulkan format of a texel encoding.
fn texel_format(encoding: TexelEncoding) -> vk::Format {
    match encoding {
        TexelEncoding::F32 => vk::Format::R32G32B32A32_SFLOAT,
        TexelEncoding::F16 => vk::Format::R16G16B16A16_SFLOAT,
        TexelEncoding::Srgb8 => vk::Format::R8G8B8A8_SRGB,
        TexelEncoding::Unorm8 => vk::Format::R8G8B8A8_UNORM,
    }
}

const TEXTURE_USAGE: vk::ImageUsageFlags =
    vk::ImageUsageFlags::from_raw(vk::ImageUsageFlags::SAMPLED.as_raw() | vk::ImageUsageFlags::TRANSFER_DST.as_raw());

/// The most precise encoding of `t` that the device can hold in one
/// allocation ([`choose_encoding`]); warns when it is not f32.
pub fn texture_encoding(device: &Device, t: &TextureImage, content: MapContent) -> Result<TexelEncoding, RenderError> {
    let extent = vk::Extent2D { width: t.width, height: t.height };
    let levels = t.levels.len() as u32;
    let mut failure = None;
    let bytes = |e: TexelEncoding| {
        match Image::memory_bytes(device, extent, levels, texel_format(e), e.texel_bytes(), TEXTURE_USAGE) {
            Ok(Some(bytes)) => bytes,
            // The device cannot make the image at all: count its texels
            // (for the message), more than it can allocate.
            Ok(None) => (chain_texels(t) * e.texel_bytes()).max(device.max_allocation_bytes + 1),
            Err(err) => {
                failure.get_or_insert(err);
                u64::MAX
            }
        }
    };
    let chosen = choose_encoding(t, content, device.max_allocation_bytes, bytes);
    if let Some(err) = failure {
        return Err(err.into());
    }
    let encoding = chosen?;
    if encoding != TexelEncoding::F32 {
        log::warn!(
            "texture `{}` ({} x {}) is stored as {encoding}: as 32-bit floats it would exceed the device's \
             largest allocation ({} MiB)",
            t.source,
            t.width,
            t.height,
            device.max_allocation_bytes >> 20
        );
    }
    Ok(encoding)
}

/// Uploads a texture with its mip chain in `encoding`, staging at most
/// [`STAGING_BYTES`] at a time.
pub fn upload_texture(
    device: &Arc<Device>,
    cmds: &mut Commands,
    t: &TextureImage,
    encoding: TexelEncoding,
) -> Result<Image, RenderError> {
    let extent = vk::Extent2D { width: t.width, height: t.height };
    let image =
        Image::with_levels(device, &t.source, extent, t.levels.len() as u32, texel_format(encoding), TEXTURE_USAGE)?;
    let texel_bytes = encoding.texel_bytes();
    let staging_size = (chain_texels(t) * texel_bytes).min(STAGING_BYTES);
    // Pieces are whole rows: the widest (16384 texels of f32) is 256 KiB.
    assert!(t.width as u64 * texel_bytes <= staging_size, "a texture row exceeds the staging buffer");
    let mut staging = Buffer::new(
        device,
        "texture upload",
        staging_size,
        vk::BufferUsageFlags::TRANSFER_SRC,
        gpu_allocator::MemoryLocation::CpuToGpu,
    )?;
    let upload = [Access::TransferWrite];
    cmds.run(|rec| {
        image.transition(rec, (&[], vk::ImageLayout::UNDEFINED), (&upload, vk::ImageLayout::TRANSFER_DST_OPTIMAL))
    })?;
    let mut regions = Vec::new();
    let mut used = 0u64;
    for (level, texels) in t.levels.iter().enumerate() {
        let width = (t.width >> level).max(1) as u64;
        let height = (t.height >> level).max(1) as u64;
        let row_bytes = width * texel_bytes;
        let mut row = 0u64;
        while row < height {
            let rows = (height - row).min((staging_size - used) / row_bytes);
            if rows == 0 {
                // Copies into other rows than the last submission's: no
                // dependency between them (the staging buffer is rewritten
                // by the host only after the fence).
                cmds.run(|rec| image.copy_from_buffer(rec.cmd, &staging, &regions))?;
                (regions, used) = (Vec::new(), 0);
                continue;
            }
            let first = (row * width) as usize;
            let piece = &texels[first..first + (rows * width) as usize];
            encoding.encode(piece, &mut staging.bytes_mut()[used as usize..(used + rows * row_bytes) as usize]);
            regions.push(image.rows_region(level as u32, row as u32, rows as u32, used));
            used += rows * row_bytes;
            row += rows;
        }
    }
    // Sampled by whichever shader stage a pass runs in.
    let readers = device.in_every_stage(Access::ShaderRead);
    cmds.run(|rec| {
        image.copy_from_buffer(rec.cmd, &staging, &regions);
        image.transition(
            rec,
            (&upload, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
            (&readers, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
        );
    })?;
    Ok(image)
}

/// Rounds a box outward to f32.
fn f32_box(b: &Aabb) -> ([f32; 3], [f32; 3]) {
    let lo = b.min.to_array().map(|v| {
        let f = v as f32;
        if f as f64 > v {
            f.next_down()
        } else {
            f
        }
    });
    let hi = b.max.to_array().map(|v| {
        let f = v as f32;
        if (f as f64) < v {
            f.next_up()
        } else {
            f
        }
    });
    (lo, hi)
}

/// How far from the GPU frame's `origin` rays can start: the farthest point
/// of any object's box (secondary rays start on surfaces; camera rays at the
/// origin) or of any light (caustic photons start on lights; a directional
/// light's start on a plane 2 radii + 1 beyond the specular objects'
/// bounding sphere, `caustics::parallel_grid`: within 3 reaches + 1).
fn scene_reach(scene: &Scene, origin: DVec3) -> f64 {
    // Camera rays start at the camera (at the origin in renders) and at each
    // keyframe's position of an animated camera.
    let keyframes = scene.camera.keyframes.iter().map(|k| (k.position - origin).length());
    let camera = keyframes.fold((scene.camera.position - origin).length(), f64::max);
    let objects = scene
        .objects
        .iter()
        .filter_map(|o| {
            // The farthest point of a box's image is one of its corners.
            let b = o.shape.bounds().ok()?;
            let corners = (0..8).map(|i| {
                let pick = |axis: usize| if i >> axis & 1 == 0 { b.min[axis] } else { b.max[axis] };
                (o.transform.transform_point3(DVec3::new(pick(0), pick(1), pick(2))) - origin).length()
            });
            Some(corners.fold(0.0, f64::max))
        })
        .fold(0.0, f64::max);
    let lights = scene.lights.iter().map(|l| match *l {
        Light::Point { position, .. } => (position - origin).length(),
        Light::Sphere { centre, radius, .. } => (centre - origin).length() + radius,
        Light::Rect { corner, edge_u, edge_v, .. } => (corner - origin).length() + edge_u.length() + edge_v.length(),
        Light::Directional { .. } => 3.0 * objects + 1.0,
    });
    lights.fold(objects.max(camera), f64::max)
}

/// How far from the GPU frame's origin a ray may start and still be near
/// the object (within 90 % of its rebase distance in its own frame;
/// `to_world` maps the object's frame to the GPU's): the object-frame origin
/// of a world point x is L⁻¹(x - t), at most ‖L⁻¹‖₂ (|x| + |t|) from the
/// object's origin. The 10 % are a margin over the f32 rounding of the
/// hardware's object ray (a ray just beyond the rebase distance is as well
/// served by the near search as one just within it: the distance is a
/// choice, not a cliff).
fn near_limit(to_world: &DAffine3, rebase_distance: f64) -> f64 {
    0.9 * rebase_distance / stretch_bound(&to_world.matrix3.inverse()) - to_world.translation.length()
}

/// An upper bound on how far `m` stretches a vector (its spectral norm):
/// the square root of the largest absolute row sum of mᵀm, which bounds
/// that matrix's largest eigenvalue (Gershgorin). Exact for rotations and
/// scalings; within 3^¼ of the norm otherwise (the Frobenius norm is within
/// √3, too loose for [`near_limit`]).
fn stretch_bound(m: &DMat3) -> f64 {
    let s = m.transpose() * *m;
    let rows = (0..3).map(|i| (0..3).map(|j| s.col(j)[i].abs()).sum::<f64>());
    rows.fold(0.0, f64::max).sqrt()
}

/// A bound, in object units, on the error of the object-frame ray the
/// hardware forms from its f32 instance transform (`to_world` rounded, then
/// inverted) for rays starting within `reach` of the frame's origin: 8 f32
/// roundings of the distances involved (the translation's, the inverse's and
/// the transform of the origin each round a few times), through the
/// inverse's largest stretch (its Frobenius norm bounds it). Seen from 1e6
/// object sizes this is about one object size; for a scene within ~30 units
/// of the camera it is below the cells' own padding, and the boxes are
/// unchanged.
fn placement_error(to_world: &DAffine3, reach: f64) -> f64 {
    let stretch = frobenius(&to_world.matrix3.inverse());
    8.0 * f64::from(f32::EPSILON) * 0.5 * stretch * (to_world.translation.length() + reach)
}

/// The Frobenius norm of a matrix: a bound on how far it stretches a vector.
fn frobenius(m: &DMat3) -> f64 {
    m.to_cols_array().iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// Row-major 3x4 matrix of an affine transform.
fn row_major_3x4(m: &DAffine3) -> [f32; 12] {
    let c = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis, m.translation];
    let mut out = [0.0f32; 12];
    for r in 0..3 {
        for (k, col) in c.iter().enumerate() {
            out[r * 4 + k] = col[r] as f32;
        }
    }
    out
}

fn storage(device: &Arc<Device>, name: &str, bytes: &[u8]) -> Result<Buffer, RenderError> {
    Ok(Buffer::with_data(device, name, bytes, vk::BufferUsageFlags::STORAGE_BUFFER)?)
}

/// The loop-budget report, cleared.
fn loop_budget_buffer(device: &Arc<Device>) -> Result<Buffer, RenderError> {
    let size = std::mem::size_of::<GpuLoopBudget>() as u64;
    let mut buffer = Buffer::storage(device, "loop budget", size, gpu_allocator::MemoryLocation::GpuToCpu)?;
    buffer.write(0, bytemuck::bytes_of(&GpuLoopBudget::default()));
    Ok(buffer)
}

impl GpuScene {
    /// Splits every object into cells and uploads the scene.
    pub fn new(
        device: &Arc<Device>,
        cmds: &mut Commands,
        scene: &Scene,
        params: &CellParams,
    ) -> Result<Self, RenderError> {
        Self::with_origin(device, cmds, scene, params, DVec3::ZERO)
    }

    /// The GPU scene of a render of `scene`: default cells, centred on the
    /// camera's render origin (`Camera::render_origin`: its position, or an
    /// animation's first keyframe), so that every command and the viewer
    /// upload a scene alike and render it to the same numbers.
    pub fn for_render(device: &Arc<Device>, cmds: &mut Commands, scene: &Scene) -> Result<Self, RenderError> {
        Self::with_origin(device, cmds, scene, &CellParams::default(), scene.camera.render_origin())
    }

    /// [`Self::new`] with the GPU's world frame centred on `origin`: object
    /// transforms and light positions are made relative to it in f64 before
    /// they are rounded to f32, so that geometry near `origin` (the camera,
    /// for renders) keeps f32's full precision however far it lies from the
    /// scene's origin. Rays given to the GPU must be relative to it too.
    pub fn with_origin(
        device: &Arc<Device>,
        cmds: &mut Commands,
        scene: &Scene,
        params: &CellParams,
        origin: DVec3,
    ) -> Result<Self, RenderError> {
        let mut objects = Vec::new();
        let mut cells: Vec<GpuCell> = Vec::new();
        let mut perturbations: Vec<GpuPerturbation> = Vec::new();
        let mut lists: Vec<u32> = Vec::new();
        let mut blases = Vec::new();
        let mut placements = Vec::new();
        let reach = scene_reach(scene, origin);
        let mut near_reach = f64::INFINITY;

        for (index, object) in scene.objects.iter().enumerate() {
            let object_cells = object
                .shape
                .cells(params)
                .map_err(|source| RenderError::Geometry { object: object.name.clone(), source })?;
            let first_perturbation = perturbations.len() as u32;
            perturbations.extend(object.shape.perturbations.iter().map(GpuPerturbation::from));
            let first_cell = cells.len() as u32;
            let relative = DAffine3::from_translation(-origin) * object.transform;
            objects.push(GpuObject::new(object, first_cell, &relative));
            near_reach = near_reach.min(near_limit(&relative, GpuObject::rebase_distance(object)));
            if object_cells.is_empty() {
                continue;
            }
            // The boxes the hardware culls with cover its f32 placement's
            // error where that exceeds the cells' own padding (far objects);
            // the root search itself keeps to the cells' bounds.
            let cell_pad = object.shape.bounds().map_or(0.0, |b| params.pad(&b));
            let grow = (placement_error(&relative, reach) - cell_pad).max(0.0);
            let mut aabbs = Vec::with_capacity(object_cells.len());
            for c in &object_cells {
                let (lo, hi) = f32_box(&c.bounds);
                let (blo, bhi) = if grow > 0.0 { f32_box(&c.bounds.padded(grow)) } else { (lo, hi) };
                aabbs.push([blo[0], blo[1], blo[2], bhi[0], bhi[1], bhi[2]]);
                cells.push(GpuCell { lo, hi, first: lists.len() as u32, count: c.perturbations.len() as u32 });
                lists.extend(c.perturbations.iter().map(|&i| first_perturbation + i));
            }
            blases.push(AccelerationStructure::bottom_level_aabbs(device, cmds, &aabbs)?);
            placements.push((blases.len() - 1, relative, index as u32));
        }

        let instances: Vec<AsInstance<'_>> = placements
            .iter()
            .map(|&(b, t, index)| AsInstance { blas: &blases[b], transform: row_major_3x4(&t), custom_index: index })
            .collect();
        let tlas = AccelerationStructure::top_level(device, cmds, &instances)?;

        let moments = scene_maps::slope_moments(scene);
        let materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let index = |t: Option<usize>| t.map_or(NO_TEXTURE, |t| t as u32);
                GpuMaterial {
                    normal_moments: index(moments.normal[i]),
                    displacement_moments: index(moments.displacement[i]),
                    ..GpuMaterial::from(m)
                }
            })
            .collect();
        let derived = moments.textures;
        let texture_count = scene.textures.len() + derived.len();
        if texture_count >= MAX_TEXTURES as usize {
            return Err(RenderError::TooManyTextures(texture_count));
        }
        let white = TextureImage { source: "white".into(), width: 1, height: 1, levels: vec![vec![[1.0; 4]]] };
        let contents = scene_maps::map_contents(scene);
        let mut textures = Vec::with_capacity(texture_count + 1);
        for (i, t) in scene.textures.iter().chain(&derived).chain([&white]).enumerate() {
            let content = contents.get(i).copied().unwrap_or(MapContent::Data);
            let encoding = texture_encoding(device, t, content)?;
            textures.push(upload_texture(device, cmds, t, encoding)?);
        }
        let (environment, env_cdf) = match scene.environment {
            Some(e) => {
                let t = &scene.textures[e.texture];
                let map = EnvironmentMap::from_texture(t, e.scale);
                (Some((e.texture as u32, t.width, t.height, e.scale)), map.cdf_buffer())
            }
            None => (None, vec![0.0f32]),
        };
        let lights: Vec<GpuLight> = scene.lights.iter().map(|l| GpuLight::relative_to(l, origin)).collect();

        let stats = GeometryStats {
            perturbations: perturbations.len(),
            cells: cells.len(),
            cell_list_entries: lists.len(),
            table_bytes: (std::mem::size_of_val(perturbations.as_slice())
                + std::mem::size_of_val(cells.as_slice())
                + std::mem::size_of_val(lists.as_slice())) as u64,
            accel_bytes: blases.iter().map(|b| b.buffer.size).sum::<u64>() + tlas.buffer.size,
        };
        Ok(Self {
            objects: storage(device, "objects", bytemuck::cast_slice(&objects))?,
            cells: storage(device, "cells", bytemuck::cast_slice(&cells))?,
            perturbations: storage(device, "perturbations", bytemuck::cast_slice(&perturbations))?,
            cell_lists: storage(device, "cell lists", bytemuck::cast_slice(&lists))?,
            materials: storage(device, "materials", bytemuck::cast_slice(&materials))?,
            light_count: lights.len() as u32,
            lights: storage(device, "lights", bytemuck::cast_slice(&lights))?,
            textures,
            sampler: Sampler::linear_repeat(device)?,
            env_cdf: storage(device, "environment tables", bytemuck::cast_slice(&env_cdf))?,
            environment,
            tlas,
            _blases: blases,
            stats,
            origin,
            loop_budget: loop_budget_buffer(device)?,
            measure_loop_budget: false,
            far_rays: reach > near_reach,
            near_reach,
        })
    }

    /// Whether a ray of the scene can start beyond an object's rebase
    /// distance (`GpuObject::rebase_distance`) and so needs the f64 far-ray
    /// search (glsl/intersection/root_search.glsl): decided from how far from the frame's
    /// origin the objects, lights and camera keyframes reach. When it
    /// cannot, the passes' shaders are specialised without that search
    /// (`SPEC_FAR_RAYS`), and near rays skip its per-candidate test.
    pub fn far_rays(&self) -> bool {
        self.far_rays
    }

    /// Keeps the far-ray search in the passes built from now on, whatever the
    /// scene's reach: for a camera that may go anywhere (the viewer).
    pub fn allow_far_rays(&mut self) {
        self.far_rays = true;
    }

    /// How far from the GPU frame's origin a ray may start and still be near
    /// every object: a pass whose rays start farther (a probe pass's given
    /// rays) needs the far-ray search even where the scene's own rays do
    /// not ([`Self::far_rays`]).
    pub fn near_reach(&self) -> f64 {
        self.near_reach
    }

    /// Turns the loop-budget measurement on or off for the passes built
    /// after this call (their shaders are specialised for it) and clears
    /// the report.
    pub fn measure_loop_budget(&mut self, on: bool) {
        self.measure_loop_budget = on;
        self.reset_loop_budget();
    }

    /// Clears the loop-budget report.
    pub fn reset_loop_budget(&mut self) {
        self.loop_budget.write(0, bytemuck::bytes_of(&GpuLoopBudget::default()));
    }

    /// What the invocations of passes built with the measurement on counted
    /// since the last reset (read after their work).
    pub fn loop_budget(&self) -> LoopBudget {
        let r: GpuLoopBudget = self.loop_budget.read()[0];
        LoopBudget { most_edges: r.most_edges, invocations: r.invocations, spent: r.spent }
    }

    /// The specialisation constants every tracing pass takes from the scene:
    /// whether it measures the loop budget, and whether rays may come from
    /// far away ([`Self::far_rays`]).
    pub fn scene_constants(&self) -> [(u32, u32); 2] {
        [(SPEC_LOOP_BUDGET, u32::from(self.measure_loop_budget)), (SPEC_FAR_RAYS, u32::from(self.far_rays))]
    }

    /// The texture array: every scene texture, the rest of the slots filled
    /// with the white texture.
    pub fn texture_binding(&self) -> (u32, Binding<'_>) {
        let white = self.textures.last().expect("the white texture");
        let images = (0..MAX_TEXTURES as usize).map(|i| self.textures.get(i).unwrap_or(white)).collect();
        (BINDING_TEXTURES, Binding::Textures(images, &self.sampler))
    }

    /// The intersection mode to specialise shaders with: `requested`, except
    /// that a scene without perturbations needs no more than the base
    /// quadrics' roots (`IntersectMode::Base`, the same hits), which leaves the
    /// perturbation code and its f64 root refinement out of the shaders:
    /// they compile several times faster on lavapipe.
    pub fn intersect_mode(&self, requested: IntersectMode) -> IntersectMode {
        if requested == IntersectMode::Full && self.stats.perturbations == 0 {
            IntersectMode::Base
        } else {
            requested
        }
    }

    /// The bindings `BINDING_TLAS..=BINDING_FRAME` of the passes that trace
    /// the scene for an image: geometry, materials, lights, and `frame`
    /// (`GpuFrame`).
    pub fn frame_bindings<'a>(&'a self, frame: &'a Buffer) -> Vec<(u32, Binding<'a>)> {
        let mut bindings = self.geometry_bindings().into_iter().collect::<Vec<_>>();
        bindings.extend([
            (BINDING_MATERIALS, Binding::Buffer(&self.materials)),
            (BINDING_LIGHTS, Binding::Buffer(&self.lights)),
            (BINDING_FRAME, Binding::Buffer(frame)),
        ]);
        bindings
    }

    /// The bindings `BINDING_TLAS..=BINDING_CELL_LISTS` shared by all
    /// passes, and the loop-budget report.
    pub fn geometry_bindings(&self) -> [(u32, Binding<'_>); 6] {
        [
            (BINDING_LOOP_BUDGET, Binding::Buffer(&self.loop_budget)),
            (BINDING_TLAS, Binding::AccelerationStructure(&self.tlas)),
            (BINDING_OBJECTS, Binding::Buffer(&self.objects)),
            (BINDING_CELLS, Binding::Buffer(&self.cells)),
            (BINDING_PERTURBATIONS, Binding::Buffer(&self.perturbations)),
            (BINDING_CELL_LISTS, Binding::Buffer(&self.cell_lists)),
        ]
    }
}

/// The camera basis of a scene for an image of the given size.
pub fn camera_basis(scene: &Scene, width: u32, height: u32) -> [DVec3; 4] {
    let c = &scene.camera;
    let forward = (c.look_at - c.position).normalize();
    let right = forward.cross(c.up).normalize();
    let up = right.cross(forward);
    let half = (0.5 * c.vfov_degrees.to_radians()).tan();
    let aspect = width as f64 / height as f64;
    [c.position, forward, right * half * aspect, up * half]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stretch bound is exact for rotations and scalings and never
    /// below the stretch of any vector.
    #[test]
    fn stretch_bound_bounds_the_spectral_norm() {
        let turn = DMat3::from_euler(glam::EulerRot::XYZ, 0.4, 1.0, -0.3);
        assert!((stretch_bound(&turn) - 1.0).abs() < 1e-12);
        assert!((stretch_bound(&DMat3::from_diagonal(DVec3::new(2.0, -3.0, 0.5))) - 3.0).abs() < 1e-12);
        let m = turn
            * DMat3::from_diagonal(DVec3::new(0.2, 5.0, 1.5))
            * DMat3::from_euler(glam::EulerRot::ZYX, 1.1, -0.2, 0.7);
        let bound = stretch_bound(&m);
        let mut most = 0.0f64;
        for i in 0..20_000 {
            let (a, b) = (i as f64 * 2.399963, (1.0 - 2.0 * (i as f64 + 0.5) / 20_000.0).acos());
            let v = DVec3::new(b.sin() * a.cos(), b.sin() * a.sin(), b.cos());
            most = most.max((m * v).length());
        }
        assert!(most <= bound && bound <= 1.32 * most, "stretch {most}, bound {bound}");
    }
}
