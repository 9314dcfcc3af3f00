//! The caustic passes (paper section 3), run before the render pass when the
//! scene has a light that emits caustic rays, a specular object and a diffuse
//! receiver ([`Scene::needs_caustics`]):
//!
//! 1. **G-buffer** (`gbuffer.comp`): the surface seen through each pixel
//!    centre: where caustics can be seen.
//! 2. **Caustic rays** (`caustic_trace.comp`): for each light (and each of
//!    `light_samples` points on a sphere light), a grid of rays aimed at the
//!    bounds of all specular objects together, traced through them until
//!    they land on a diffuse surface.
//! 3. **Caustic cells** (`caustic_splat.comp`): each 2x2 block of grid
//!    neighbours that followed the same surfaces is a cell; its landing area
//!    gives the irradiance, interpolated between its corners and added to
//!    the pixels whose receiver lies in it (the caustic map).
//! 4. **Caustic beams** (`caustic_beams.comp`, with fog only): coarser cells
//!    of the rays' last segments through the fog scatter light toward the
//!    camera (volumetric caustics, the beam map).
//!
//! The render pass adds the caustic map at the primary diffuse vertex and
//! the beam map on the camera ray's first segment, and leaves out the paths
//! they cover.

use std::sync::Arc;

use glam::{DVec2, DVec3};

pub use super::film::CausticReport;
use super::gpu::{CausticPush, GpuCausticRay, GpuEmitter, GpuReceiver};
use super::scene_gpu::GpuScene;
use super::tracer::Tracer;
use super::IntersectMode;
use super::RenderError;
use crate::gpu::shader_interface::{
    BEAM_STRIDE, BINDING_CAUSTIC_BEAMS, BINDING_CAUSTIC_MAP, BINDING_CAUSTIC_RAYS, BINDING_GBUFFER,
    CAUSTIC_FIXED_POINT, CAUSTIC_GROUP, EMITTER_PARALLEL, EMITTER_POINT, RENDER_GROUP, SPEC_INTERSECT_MODE,
    SPEC_MEDIA_ENABLED,
};
use crate::gpu::shaders;
use crate::model::geometry::CellParams;
use crate::model::scene::{Light, Scene};
use crate::vk::{
    Access, Backend, Binding, Buffer, Commands, ComputePipeline, Device, GpuTimer, MemoryLocation, ShaderStage,
};

/// The caustic passes: their pipelines, the rays, and the results that the
/// render pass binds. [`CausticMap::new`] builds them for one image size and
/// set of emission grids; [`CausticMap::run`] (re)computes the maps for the
/// camera currently in the frame buffer.
pub struct CausticMap {
    gbuffer: Tracer,
    trace: Tracer,
    splat: ComputePipeline,
    beam: ComputePipeline,
    /// The caustic rays' landing points (`GpuCausticRay`).
    rays: Buffer,
    /// Receiver per pixel (`GpuReceiver`).
    pub receivers: Buffer,
    /// Fixed-point irradiance per pixel (three `u64`).
    pub map: Buffer,
    /// Fixed-point radiance of the volumetric caustics per pixel (three `u64`).
    pub beams: Buffer,
    /// True when the beam pass runs (the scene has fog).
    pub has_beams: bool,
    grids: Vec<GpuEmitter>,
    size: (u32, u32),
    /// What was done.
    pub report: CausticReport,
}

/// Two grids per light and light sample (one whose rays refract at glass, one
/// whose rays reflect at the first glass they meet), each aimed at the
/// bounds of all the specular objects (one grid, so that no ray is counted twice where specular
/// objects nest, like water in a glass vessel). Positions are relative to
/// `origin` (the GPU frame's), computed in f64; each grid has about `rays`
/// rays. `None` when a light sits inside those bounds
/// (no grid plane in front of it can see them all).
pub fn emitters(scene: &Scene, origin: DVec3, max_specular: u32, rays: u32) -> Option<Vec<GpuEmitter>> {
    let corners: Vec<DVec3> = specular_corners(scene).into_iter().map(|c| c - origin).collect();
    if corners.is_empty() {
        return Some(Vec::new());
    }
    let centre_rel = corners.iter().fold(DVec3::ZERO, |a, &c| a + c) / corners.len() as f64;
    let radius = corners.iter().map(|c| c.distance(centre_rel)).fold(0.0, f64::max);
    let mut out = Vec::new();
    for light in scene.lights.iter().filter(|l| l.emits_caustic_rays()) {
        match *light {
            Light::Point { position, intensity } => {
                out.push(point_grid(position - origin, intensity.as_dvec3(), &corners, centre_rel, rays)?);
            }
            Light::Sphere { centre: c, radius: r, radiance } => {
                // A sphere of radiance L has intensity L π r² in every
                // direction; the rays leave from points of its disk facing
                // the targets, one grid per point.
                let k = scene.caustics.light_samples.max(1);
                let intensity = radiance.as_dvec3() * (std::f64::consts::PI * r * r / k as f64);
                let w = (centre_rel + origin - c).normalize_or(DVec3::Z);
                let (u, v) = w.any_orthonormal_pair();
                for i in 0..k {
                    // Fibonacci points over the disk (equal areas).
                    let rho = r * ((i as f64 + 0.5) / k as f64).sqrt();
                    let phi = i as f64 * 2.399_963_229_728_653;
                    let p = c + rho * (phi.cos() * u + phi.sin() * v);
                    out.push(point_grid(p - origin, intensity, &corners, centre_rel, rays)?);
                }
            }
            Light::Directional { direction, irradiance } => {
                out.push(parallel_grid(-direction, irradiance.as_dvec3(), &corners, centre_rel, radius, rays));
            }
            Light::Rect { .. } => {}
        }
    }
    // Beside each grid, the same rays reflected at their first specular
    // vertex when it is glass (caustic_trace.glsl): the light reflected off
    // glass onto the floor and into the fog.
    let reflected: Vec<GpuEmitter> = out.iter().map(|e| GpuEmitter { reflect_first: 1, ..*e }).collect();
    out.extend(reflected);
    let mut first = 0u32;
    for e in &mut out {
        e.first_ray = first;
        e.max_specular = max_specular;
        first += e.grid[0] * e.grid[1];
    }
    Some(out)
}

/// World corners of the cells of every specular object.
fn specular_corners(scene: &Scene) -> Vec<DVec3> {
    let mut corners = Vec::new();
    for object in scene.objects.iter().filter(|o| scene.materials[o.material].is_specular()) {
        let Ok(cells) = object.shape.cells(&CellParams::default()) else { continue };
        for cell in cells {
            let (lo, hi) = (cell.bounds.min, cell.bounds.max);
            for k in 0..8 {
                let p = DVec3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                );
                corners.push(object.transform.transform_point3(p));
            }
        }
    }
    corners
}

/// Grid dimensions with about `rays` rays over a rectangle of `size`, with
/// square grid cells.
fn grid_for(size: DVec2, rays: u32) -> [u32; 2] {
    let aspect = (size.x / size.y.max(1e-30)).clamp(1e-3, 1e3);
    let nx = ((rays as f64 * aspect).sqrt().round() as u32).max(2);
    let ny = (rays / nx).max(2);
    [nx, ny]
}

/// The rectangle in the plane spanned by `u`, `v` that bounds `corners`
/// mapped to it by `to_plane` (`None` from `to_plane` fails the whole).
fn plane_bounds(corners: &[DVec3], to_plane: impl Fn(DVec3) -> Option<DVec2>) -> Option<(DVec2, DVec2)> {
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    for &c in corners {
        let xy = to_plane(c)?;
        lo = lo.min(xy);
        hi = hi.max(xy);
    }
    Some((lo, hi))
}

/// An emission grid of `kind` over [lo, hi] of the plane (u, v) with axis w.
fn grid_emitter(kind: u32, origin: DVec3, w: DVec3, (lo, hi): (DVec2, DVec2), rays: u32, power: DVec3) -> GpuEmitter {
    let (u, v) = w.any_orthonormal_pair();
    GpuEmitter {
        origin: origin.as_vec3().to_array(),
        kind,
        u: u.as_vec3().to_array(),
        v: v.as_vec3().to_array(),
        w: w.as_vec3().to_array(),
        lo: lo.as_vec2().to_array(),
        hi: hi.as_vec2().to_array(),
        grid: grid_for(hi - lo, rays),
        power: power.as_vec3().to_array(),
        ..Default::default()
    }
}

/// Rays from `p` over the tangent-plane rectangle (at distance 1 along the
/// axis toward `centre`) that bounds `corners`; `None` when a corner is not
/// in front of `p`.
fn point_grid(p: DVec3, intensity: DVec3, corners: &[DVec3], centre: DVec3, rays: u32) -> Option<GpuEmitter> {
    let w = (centre - p).normalize_or(DVec3::Z);
    let (u, v) = w.any_orthonormal_pair();
    let bounds = plane_bounds(corners, |c| {
        let r = c - p;
        let z = r.dot(w);
        (z > 1e-6 * r.length()).then(|| DVec2::new(r.dot(u), r.dot(v)) / z)
    })?;
    Some(grid_emitter(EMITTER_POINT, p, w, bounds, rays, intensity))
}

/// Parallel rays along `w` over the rectangle that bounds `corners` in the
/// plane across `w`, starting well outside the bounds.
fn parallel_grid(w: DVec3, irradiance: DVec3, corners: &[DVec3], centre: DVec3, radius: f64, rays: u32) -> GpuEmitter {
    let w = w.normalize();
    let (u, v) = w.any_orthonormal_pair();
    let bounds = plane_bounds(corners, |c| Some(DVec2::new((c - centre).dot(u), (c - centre).dot(v))))
        .expect("parallel projection always succeeds");
    grid_emitter(EMITTER_PARALLEL, centre - w * (2.0 * radius + 1.0), w, bounds, rays, irradiance)
}

impl CausticMap {
    /// What the render pass reads from the caustic passes: the receivers,
    /// the caustic map and the beam map, or `placeholder` at each binding
    /// where the passes did not run (`map` is `None`).
    pub fn render_bindings<'a>(map: Option<&'a CausticMap>, placeholder: &'a Buffer) -> [(u32, Binding<'a>); 3] {
        [
            (BINDING_GBUFFER, Binding::Buffer(map.map_or(placeholder, |c| &c.receivers))),
            (BINDING_CAUSTIC_MAP, Binding::Buffer(map.map_or(placeholder, |c| &c.map))),
            (BINDING_CAUSTIC_BEAMS, Binding::Buffer(map.map_or(placeholder, |c| &c.beams))),
        ]
    }

    /// Creates the pipelines and buffers for a `width` x `height` image whose
    /// frame parameters are in `frame`; nothing runs yet. The G-buffer and
    /// the caustic rays trace with `backend`.
    pub fn new(
        device: &Arc<Device>,
        gpu: &GpuScene,
        scene: &Scene,
        frame: &Buffer,
        (width, height): (u32, u32),
        grids: &[GpuEmitter],
        backend: Backend,
    ) -> Result<Self, RenderError> {
        let pixels = width as u64 * height as u64;
        let ray_count: u64 = grids.iter().map(|g| g.grid[0] as u64 * g.grid[1] as u64).sum();
        let rays = Buffer::storage(
            device,
            "caustic rays",
            ray_count.max(1) * std::mem::size_of::<GpuCausticRay>() as u64,
            MemoryLocation::GpuToCpu,
        )?;
        let receivers = Buffer::storage(
            device,
            "receivers",
            pixels * std::mem::size_of::<GpuReceiver>() as u64,
            MemoryLocation::GpuOnly,
        )?;
        let map = Buffer::storage(device, "caustic map", pixels * 24, MemoryLocation::GpuToCpu)?;
        let beams = Buffer::storage(device, "beam map", pixels * 24, MemoryLocation::GpuToCpu)?;
        let has_beams = scene.fog.is_some_and(|f| f.density > 0.0);
        let intersect = gpu.intersect_mode(IntersectMode::Full).constant();
        let traced = [[(SPEC_INTERSECT_MODE, intersect)].as_slice(), &gpu.scene_constants()].concat();
        let gbuffer = Tracer::new(device, backend, shaders::gbuffer, shaders::gbuffer_rgen, &traced)?;
        let trace = Tracer::new(
            device,
            backend,
            shaders::caustic_trace,
            shaders::caustic_trace_rgen,
            &[
                [(SPEC_INTERSECT_MODE, intersect), (SPEC_MEDIA_ENABLED, u32::from(scene.has_media()))].as_slice(),
                &traced[1..],
            ]
            .concat(),
        )?;
        let splat = ComputePipeline::new(device, &shaders::caustic_splat(), &[])?;
        let beam = ComputePipeline::new(device, &shaders::caustic_beams(), &[])?;
        let mut bindings = gpu.frame_bindings(frame);
        bindings.extend([
            (BINDING_CAUSTIC_RAYS, Binding::Buffer(&rays)),
            (BINDING_GBUFFER, Binding::Buffer(&receivers)),
            (BINDING_CAUSTIC_MAP, Binding::Buffer(&map)),
            (BINDING_CAUSTIC_BEAMS, Binding::Buffer(&beams)),
        ]);
        gbuffer.bind(&bindings)?;
        trace.bind(&bindings)?;
        splat.bind(&bindings)?;
        beam.bind(&bindings)?;
        let report = CausticReport { rays: ray_count, grids: grids.len(), ..Default::default() };
        Ok(Self {
            gbuffer,
            trace,
            splat,
            beam,
            rays,
            receivers,
            map,
            beams,
            has_beams,
            grids: grids.to_vec(),
            size: (width, height),
            report,
        })
    }

    /// Computes the caustic (and beam) maps for the camera in the frame
    /// buffer, timing each pass with `timer`.
    pub fn run(&mut self, cmds: &mut Commands, timer: &GpuTimer) -> Result<(), RenderError> {
        let (width, height) = self.size;
        let Self { gbuffer, trace, splat, beam, map, beams, grids, report, .. } = self;
        // The tracing passes run in their backend's stage, splat and beams
        // in compute shaders; the render pass (same backend) reads all.
        let traced = gbuffer.stage();
        let (tracing, compute) = (Access::ShaderWrite(traced), Access::ShaderWrite(ShaderStage::Compute));
        let ((), t) = timer.run(cmds, |rec| {
            // A previous run's render read the maps and the G-buffer, its
            // splat and beams wrote the maps.
            rec.barrier(&[Access::ShaderRead(traced), compute], &[Access::TransferWrite, tracing]);
            map.fill(rec, 0);
            beams.fill(rec, 0);
            gbuffer.run(rec.cmd, &[], [width, height], [RENDER_GROUP, RENDER_GROUP]);
        })?;
        report.gbuffer_seconds = t;

        let ((), t) = timer.run(cmds, |rec| {
            // The rays start from the G-buffer's receivers.
            rec.barrier(&[tracing], &[tracing]);
            for (i, g) in grids.iter().enumerate() {
                // Each grid writes its own range of the rays; the
                // synchronisation checks see the whole buffer (1.4 layers),
                // so the grids are ordered (free on lavapipe, which runs
                // them in order anyway).
                if i > 0 {
                    rec.barrier(&[tracing], &[tracing]);
                }
                trace.run(
                    rec.cmd,
                    bytemuck::bytes_of(&CausticPush { emitter: *g }),
                    [g.grid[0] * g.grid[1], 1],
                    [CAUSTIC_GROUP, 1],
                );
            }
        })?;
        report.trace_seconds = t;

        let ((), t) = timer.run(cmds, |rec| {
            // Splats read the rays and add into the cleared map; each
            // grid's splats add into the same pixels as the last grid's.
            rec.barrier(&[tracing, Access::TransferWrite], &[compute]);
            for (i, g) in grids.iter().enumerate() {
                if i > 0 {
                    rec.barrier(&[compute], &[compute]);
                }
                let cells = (g.grid[0] - 1) * (g.grid[1] - 1);
                splat.dispatch(
                    rec.cmd,
                    bytemuck::bytes_of(&CausticPush { emitter: *g }),
                    [cells.div_ceil(CAUSTIC_GROUP), 1, 1],
                );
            }
        })?;
        report.splat_seconds = t;

        if self.has_beams {
            let ((), t) = timer.run(cmds, |rec| {
                // Beams read the rays and add into the cleared beam map.
                rec.barrier(&[tracing, Access::TransferWrite, compute], &[compute]);
                for (i, g) in grids.iter().enumerate() {
                    if i > 0 {
                        rec.barrier(&[compute], &[compute]);
                    }
                    let count = ((g.grid[0] - 1) / BEAM_STRIDE) * ((g.grid[1] - 1) / BEAM_STRIDE);
                    beam.dispatch(
                        rec.cmd,
                        bytemuck::bytes_of(&CausticPush { emitter: *g }),
                        [count.div_ceil(CAUSTIC_GROUP).max(1), 1, 1],
                    );
                }
            })?;
            report.beam_seconds = t;
        }
        Ok(())
    }

    /// Reads back how many rays landed and the caustic irradiance per pixel
    /// into [`CausticMap::report`] (the whole ray buffer and map: tests and
    /// the command line's summary use them, the viewer does not).
    pub fn read_statistics(&mut self) {
        let pixels = self.size.0 as usize * self.size.1 as usize;
        let landed: Vec<GpuCausticRay> = self.rays.read();
        self.report.landed = landed.iter().take(self.report.rays as usize).filter(|r| r.path != 0).count() as u64;
        let fixed: Vec<u64> = self.map.read();
        let scale = 1.0 / CAUSTIC_FIXED_POINT as f64;
        self.report.irradiance = fixed
            .chunks_exact(3)
            .take(pixels)
            .map(|c| [(c[0] as f64 * scale) as f32, (c[1] as f64 * scale) as f32, (c[2] as f64 * scale) as f32])
            .collect();
    }
}
