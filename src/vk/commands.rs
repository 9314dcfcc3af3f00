//! Recording and submitting command buffers, waiting on a fence.

use std::sync::Arc;

use ash::vk;

use super::sync::{Access, Recording};
use super::{Device, VkError};

/// One reusable command buffer with its pool and fence.
pub struct Commands {
    device: Arc<Device>,
    pool: vk::CommandPool,
    /// The command buffer.
    pub cmd: vk::CommandBuffer,
    fence: vk::Fence,
    /// Every write a submission may make, made visible to the host at its
    /// end (derived once: `run` is called once per dispatch).
    written: Vec<Access>,
}

impl Commands {
    /// Creates a command pool, one primary command buffer and a fence.
    pub fn new(device: &Arc<Device>) -> Result<Self, VkError> {
        let raw = &device.raw;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(device.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: `raw` is the live device (held by the Arc); `pool_info` is a local naming
        // `device.queue_family`, the family the device was created with a queue of.
        let pool = unsafe { raw.create_command_pool(&pool_info, None) }?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: `pool` was just created on `raw` and no other thread has it; `alloc` asks for one primary
        // command buffer from it.
        let cmd = match unsafe { raw.allocate_command_buffers(&alloc) } {
            Ok(c) => c[0],
            Err(e) => {
                // SAFETY: allocation failed, so `pool` holds no command buffers; it is not used after this.
                unsafe { raw.destroy_command_pool(pool, None) };
                return Err(e.into());
            }
        };
        // SAFETY: `raw` is the live device; the create info is a default one (unsignalled, no pNext), alive
        // for the call.
        let fence = match unsafe { raw.create_fence(&vk::FenceCreateInfo::default(), None) } {
            Ok(f) => f,
            Err(e) => {
                // SAFETY: `cmd` was allocated but never recorded or submitted, so destroying `pool` (which
                // frees it) is allowed; neither is used after this.
                unsafe { raw.destroy_command_pool(pool, None) };
                return Err(e.into());
            }
        };
        let mut written = vec![Access::TransferWrite, Access::AccelerationStructureBuild];
        written.extend(device.in_every_stage(Access::ShaderWrite));
        Ok(Self { device: device.clone(), pool, cmd, fence, written })
    }

    /// Records commands with `record`, submits them and waits until done.
    /// The submission ends with a barrier that makes its writes visible to
    /// the host (which reads mapped buffers once the fence is signalled);
    /// dependencies between submissions are the passes' own barriers.
    pub fn run<R>(&mut self, record: impl FnOnce(Recording<'_>) -> R) -> Result<R, VkError> {
        let raw = &self.device.raw;
        let rec = Recording { device: raw, cmd: self.cmd };
        // SAFETY: the command buffer belongs to this pool, which only this
        // thread uses (`&mut self`); the fence wait below ends its use by
        // the device before it is reset again.
        unsafe {
            raw.reset_command_buffer(self.cmd, vk::CommandBufferResetFlags::empty())?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            raw.begin_command_buffer(self.cmd, &begin)?;
            let out = record(rec);
            rec.barrier(&self.written, &[Access::HostRead]);
            raw.end_command_buffer(self.cmd)?;
            let cmds = [self.cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            raw.reset_fences(&[self.fence])?;
            raw.queue_submit(self.device.queue, &submit, self.fence)?;
            raw.wait_for_fences(&[self.fence], true, u64::MAX)?;
            Ok(out)
        }
    }
}

impl Drop for Commands {
    fn drop(&mut self) {
        // SAFETY: after device_wait_idle no submission of `cmd` is pending and nothing waits on the fence;
        // the fence and the pool (which frees `cmd`) were created in `new` on `self.device`, are destroyed
        // once, here, and `self.device` (a field) outlives this body.
        unsafe {
            let _ = self.device.raw.device_wait_idle();
            self.device.raw.destroy_fence(self.fence, None);
            self.device.raw.destroy_command_pool(self.pool, None);
        }
    }
}
