//! Typed synchronisation: a barrier is described by the accesses before it
//! and the accesses after it (in the manner of the `vk-sync` crate that
//! kajiya and screen-13 use), never by hand-written stage and access masks.
//!
//! Every access names the pipeline stage that makes it: a shader access is
//! either a compute shader's (ray queries and the plain compute passes) or a
//! ray-tracing pipeline's (`RAY_TRACING_SHADER_KHR`: ray generation,
//! intersection, closest hit, miss). A barrier that names the wrong one
//! orders nothing under the Vulkan specification, even where a serial
//! driver (lavapipe) hides it; the synchronisation checks of the validation
//! layer (on in the tests) see it.

use ash::vk;

use super::Backend;

/// The shader stage that runs a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShaderStage {
    /// A compute shader (ray queries, or no tracing at all).
    Compute,
    /// The stages of a ray-tracing pipeline.
    RayTracing,
}

impl From<Backend> for ShaderStage {
    fn from(backend: Backend) -> Self {
        match backend {
            Backend::RayQuery => ShaderStage::Compute,
            Backend::Pipeline => ShaderStage::RayTracing,
        }
    }
}

impl ShaderStage {
    fn flags(self) -> vk::PipelineStageFlags {
        match self {
            ShaderStage::Compute => vk::PipelineStageFlags::COMPUTE_SHADER,
            ShaderStage::RayTracing => vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR,
        }
    }
}

/// One kind of access to a resource by one stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// Read by a transfer command (a copy's source).
    TransferRead,
    /// Written by a transfer command (fill, clear, a copy's destination).
    TransferWrite,
    /// Read by shaders of a stage (storage and uniform buffers, storage and
    /// sampled images).
    ShaderRead(ShaderStage),
    /// Written, or read and written, by shaders of a stage.
    ShaderWrite(ShaderStage),
    /// Traced by shaders of a stage (an acceleration structure read by ray
    /// queries or `traceRays`).
    Trace(ShaderStage),
    /// Read as the arguments of an indirect dispatch.
    IndirectRead,
    /// Written by an acceleration-structure build (which also reads its
    /// inputs, a TLAS build its BLASes).
    AccelerationStructureBuild,
    /// Read by the host through mapped memory, after a fence.
    HostRead,
    /// Written by the host through mapped memory, before a submission.
    HostWrite,
}

impl Access {
    fn stage(self) -> vk::PipelineStageFlags {
        match self {
            Access::TransferRead | Access::TransferWrite => vk::PipelineStageFlags::TRANSFER,
            Access::ShaderRead(s) | Access::ShaderWrite(s) | Access::Trace(s) => s.flags(),
            Access::AccelerationStructureBuild => vk::PipelineStageFlags::ACCELERATION_STRUCTURE_BUILD_KHR,
            Access::IndirectRead => vk::PipelineStageFlags::DRAW_INDIRECT,
            Access::HostRead | Access::HostWrite => vk::PipelineStageFlags::HOST,
        }
    }

    fn access(self) -> vk::AccessFlags {
        match self {
            Access::TransferRead => vk::AccessFlags::TRANSFER_READ,
            Access::TransferWrite => vk::AccessFlags::TRANSFER_WRITE,
            Access::ShaderRead(_) => vk::AccessFlags::SHADER_READ,
            Access::ShaderWrite(_) => vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
            Access::Trace(_) => vk::AccessFlags::ACCELERATION_STRUCTURE_READ_KHR,
            Access::IndirectRead => vk::AccessFlags::INDIRECT_COMMAND_READ,
            Access::AccelerationStructureBuild => {
                vk::AccessFlags::ACCELERATION_STRUCTURE_READ_KHR | vk::AccessFlags::ACCELERATION_STRUCTURE_WRITE_KHR
            }
            Access::HostRead => vk::AccessFlags::HOST_READ,
            Access::HostWrite => vk::AccessFlags::HOST_WRITE,
        }
    }

    fn is_write(self) -> bool {
        matches!(
            self,
            Access::TransferWrite | Access::ShaderWrite(_) | Access::AccelerationStructureBuild | Access::HostWrite
        )
    }

    /// The write part of this access, as the source of a memory dependency.
    fn written(self) -> vk::AccessFlags {
        match self {
            Access::TransferWrite => vk::AccessFlags::TRANSFER_WRITE,
            Access::ShaderWrite(_) => vk::AccessFlags::SHADER_WRITE,
            Access::AccelerationStructureBuild => vk::AccessFlags::ACCELERATION_STRUCTURE_WRITE_KHR,
            Access::HostWrite => vk::AccessFlags::HOST_WRITE,
            _ => vk::AccessFlags::empty(),
        }
    }
}

/// The stage and access masks of a dependency from the accesses `prev` to
/// the accesses `next`: the source stages are `prev`'s, the destination
/// stages `next`'s; memory is made available only where `prev` wrote (a read
/// followed by a write needs an execution dependency alone) and visible to
/// every access of `next`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dependency {
    /// Stages that must finish first.
    pub src_stages: vk::PipelineStageFlags,
    /// Writes made available.
    pub src_access: vk::AccessFlags,
    /// Stages that wait.
    pub dst_stages: vk::PipelineStageFlags,
    /// Accesses the writes are made visible to.
    pub dst_access: vk::AccessFlags,
}

impl Dependency {
    /// The dependency from `prev` to `next` (empty sides wait on, or make
    /// wait, nothing: top and bottom of pipe).
    pub fn between(prev: &[Access], next: &[Access]) -> Self {
        let fold = |list: &[Access], f: fn(Access) -> vk::PipelineStageFlags| {
            list.iter().fold(vk::PipelineStageFlags::empty(), |m, a| m | f(*a))
        };
        let mut src_stages = fold(prev, Access::stage);
        let mut dst_stages = fold(next, Access::stage);
        if src_stages.is_empty() {
            src_stages = vk::PipelineStageFlags::TOP_OF_PIPE;
        }
        if dst_stages.is_empty() {
            dst_stages = vk::PipelineStageFlags::BOTTOM_OF_PIPE;
        }
        let src_access = prev.iter().fold(vk::AccessFlags::empty(), |m, a| m | a.written());
        let dst_access = if prev.iter().any(|a| a.is_write()) {
            next.iter().fold(vk::AccessFlags::empty(), |m, a| m | a.access())
        } else {
            vk::AccessFlags::empty()
        };
        Self { src_stages, src_access, dst_stages, dst_access }
    }
}

/// A command buffer being recorded, with the device that records into it:
/// what [`super::Commands::run`] hands to its closure.
#[derive(Clone, Copy)]
pub struct Recording<'a> {
    pub(super) device: &'a ash::Device,
    /// The command buffer.
    pub cmd: vk::CommandBuffer,
}

impl Recording<'_> {
    /// Records a global memory barrier from the accesses `prev` to `next`.
    pub fn barrier(&self, prev: &[Access], next: &[Access]) {
        let d = Dependency::between(prev, next);
        let barrier = [vk::MemoryBarrier::default().src_access_mask(d.src_access).dst_access_mask(d.dst_access)];
        self.pipeline_barrier(&d, &barrier, &[]);
    }

    /// Records an image memory barrier (with a layout transition from
    /// `from` to `to`) over `range` of `image`, which the caller keeps
    /// alive until the submission has finished.
    pub(super) fn image_barrier(
        &self,
        image: vk::Image,
        range: vk::ImageSubresourceRange,
        (prev, from): (&[Access], vk::ImageLayout),
        (next, to): (&[Access], vk::ImageLayout),
    ) {
        let d = Dependency::between(prev, next);
        // A layout transition is a write: what follows must see it even
        // where `prev` only read.
        let dst_access = next.iter().fold(d.dst_access, |m, a| m | a.access());
        let barrier = [vk::ImageMemoryBarrier::default()
            .src_access_mask(d.src_access)
            .dst_access_mask(if from == to { d.dst_access } else { dst_access })
            .old_layout(from)
            .new_layout(to)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(range)];
        self.pipeline_barrier(&d, &[], &barrier);
    }

    fn pipeline_barrier(&self, d: &Dependency, memory: &[vk::MemoryBarrier], images: &[vk::ImageMemoryBarrier]) {
        // SAFETY: `cmd` is in the recording state (Commands::run began it);
        // the masks name stages of enabled features only (a ray-tracing
        // access exists only where a pipeline-backend pass runs); the
        // images are alive (their owners outlive the submission).
        unsafe {
            self.device.cmd_pipeline_barrier(
                self.cmd,
                d.src_stages,
                d.dst_stages,
                vk::DependencyFlags::empty(),
                memory,
                &[],
                images,
            )
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fill_before_a_ray_generation_shader_waits_on_transfer_and_blocks_the_ray_tracing_stage() {
        let d = Dependency::between(&[Access::TransferWrite], &[Access::ShaderWrite(ShaderStage::RayTracing)]);
        assert_eq!(d.src_stages, vk::PipelineStageFlags::TRANSFER);
        assert_eq!(d.dst_stages, vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR);
        assert_eq!(d.src_access, vk::AccessFlags::TRANSFER_WRITE);
        assert_eq!(d.dst_access, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
    }

    #[test]
    fn a_read_before_a_write_needs_only_an_execution_dependency() {
        let d = Dependency::between(&[Access::TransferRead], &[Access::ShaderWrite(ShaderStage::Compute)]);
        assert_eq!(d.src_stages, vk::PipelineStageFlags::TRANSFER);
        assert_eq!(d.dst_stages, vk::PipelineStageFlags::COMPUTE_SHADER);
        assert!(d.src_access.is_empty() && d.dst_access.is_empty());
    }

    #[test]
    fn builds_then_traces_make_the_structure_visible_to_both_stages() {
        let d = Dependency::between(
            &[Access::AccelerationStructureBuild],
            &[
                Access::AccelerationStructureBuild,
                Access::Trace(ShaderStage::Compute),
                Access::Trace(ShaderStage::RayTracing),
            ],
        );
        assert_eq!(
            d.dst_stages,
            vk::PipelineStageFlags::ACCELERATION_STRUCTURE_BUILD_KHR
                | vk::PipelineStageFlags::COMPUTE_SHADER
                | vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR
        );
        assert_eq!(d.src_access, vk::AccessFlags::ACCELERATION_STRUCTURE_WRITE_KHR);
        assert!(d.dst_access.contains(vk::AccessFlags::ACCELERATION_STRUCTURE_READ_KHR));
    }

    #[test]
    fn empty_sides_are_top_and_bottom_of_pipe() {
        let d = Dependency::between(&[], &[]);
        assert_eq!(
            (d.src_stages, d.dst_stages),
            (vk::PipelineStageFlags::TOP_OF_PIPE, vk::PipelineStageFlags::BOTTOM_OF_PIPE)
        );
        assert!(d.src_access.is_empty() && d.dst_access.is_empty());
    }
}
