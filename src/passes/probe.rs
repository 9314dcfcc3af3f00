//! The probe pass: closest hits of an explicit list of rays. Used by the
//! GPU-vs-CPU geometry tests and by the ray-throughput benchmark.

use std::sync::Arc;

use super::gpu::{GpuHit, GpuRay, ProbePush};
use super::scene_gpu::GpuScene;
use super::tracer::Tracer;
use super::IntersectMode;
use super::RenderError;
use crate::gpu::shader_interface::{
    BINDING_PROBE_HITS, BINDING_PROBE_RAYS, PROBE_GROUP, SPEC_INTERSECT_MODE, SPEC_PROBE_CURVATURE,
};
use crate::gpu::shaders;
use crate::vk::{
    vk, Access, Backend, Binding, Buffer, Commands, Device, MemoryLocation, Recording, ShaderStage, Timestamps,
};

/// Rays per dispatch: short enough never to trip a driver watchdog.
const RAYS_PER_DISPATCH: u32 = 1 << 16;

/// A ray-tracing pass over a fixed ray list.
pub struct ProbePass {
    tracer: Tracer,
    // Bound to the tracer: kept alive with it.
    _rays: Buffer,
    hits: Buffer,
    count: u32,
    timestamps: Timestamps,
}

impl ProbePass {
    /// Uploads `rays` and binds them with the scene; `mode` is how candidate
    /// boxes are intersected (`IntersectMode::Full` for the real intersection);
    /// `curvature` asks for the hits' curvatures (zero otherwise).
    pub fn new(
        device: &Arc<Device>,
        scene: &GpuScene,
        rays: &[GpuRay],
        mode: IntersectMode,
        curvature: bool,
    ) -> Result<Self, RenderError> {
        Self::with_backend(device, scene, rays, mode, curvature, device.backend_for(None)?)
    }

    /// [`ProbePass::new`] tracing with `backend`: ray queries (`probe.comp`)
    /// or a ray-tracing pipeline (`probe.rgen` with the intersection shader).
    pub fn with_backend(
        device: &Arc<Device>,
        scene: &GpuScene,
        rays: &[GpuRay],
        mode: IntersectMode,
        curvature: bool,
        backend: Backend,
    ) -> Result<Self, RenderError> {
        let [budget, (far_id, far)] = scene.scene_constants();
        // The given rays may start anywhere: farther than the scene's own.
        let reach = rays.iter().map(|r| glam::Vec3::from(r.origin).length() as f64).fold(0.0, f64::max);
        let far = (far_id, far.max(u32::from(reach > scene.near_reach())));
        let spec = [(SPEC_INTERSECT_MODE, mode.constant()), (SPEC_PROBE_CURVATURE, u32::from(curvature)), budget, far];
        let tracer = Tracer::new(device, backend, shaders::probe, shaders::probe_rgen, &spec)?;
        let rays_buf = Buffer::with_data(device, "probe rays", rays, vk::BufferUsageFlags::STORAGE_BUFFER)?;
        let hits = Buffer::storage(
            device,
            "probe hits",
            (rays.len() * std::mem::size_of::<GpuHit>()) as u64,
            MemoryLocation::GpuToCpu,
        )?;
        let mut bindings = scene.geometry_bindings().into_iter().collect::<Vec<_>>();
        bindings
            .extend([(BINDING_PROBE_RAYS, Binding::Buffer(&rays_buf)), (BINDING_PROBE_HITS, Binding::Buffer(&hits))]);
        tracer.bind(&bindings)?;
        let timestamps = Timestamps::new(device, 2)?;
        Ok(Self { tracer, _rays: rays_buf, hits, count: rays.len() as u32, timestamps })
    }

    /// Traces every ray; returns the hits and the GPU time in nanoseconds.
    pub fn run(&self, cmds: &mut Commands) -> Result<(Vec<GpuHit>, f64), RenderError> {
        let written = [Access::ShaderWrite(self.stage())];
        cmds.run(|rec| {
            // An earlier run wrote the same hits.
            rec.barrier(&written, &written);
            self.record(rec);
        })?;
        let ts = self.timestamps.read_ns()?;
        let mut hits: Vec<GpuHit> = self.hits.read();
        hits.truncate(self.count as usize);
        Ok((hits, ts[1] - ts[0]))
    }

    /// Records the pass into `rec` (timestamps around the dispatches),
    /// with no barrier: the caller orders it after what came before.
    pub fn record(&self, rec: Recording<'_>) {
        self.timestamps.reset(rec.cmd);
        self.timestamps.write(rec.cmd, 0);
        let mut first = 0;
        let written = [Access::ShaderWrite(self.stage())];
        while first < self.count {
            // Each dispatch writes its own range of the hits; the 1.4
            // validation layer sees the whole buffer, so they are ordered.
            if first > 0 {
                rec.barrier(&written, &written);
            }
            let n = (self.count - first).min(RAYS_PER_DISPATCH);
            let push = ProbePush { first, count: n };
            self.tracer.run(rec.cmd, bytemuck::bytes_of(&push), [n, 1], [PROBE_GROUP, 1]);
            first += n;
        }
        self.timestamps.write(rec.cmd, 1);
    }

    /// The shader stage the pass runs in (its backend's).
    pub fn stage(&self) -> ShaderStage {
        self.tracer.stage()
    }

    /// The hits buffer the pass writes (`GpuHit` per ray).
    pub fn hits(&self) -> &Buffer {
        &self.hits
    }
}
