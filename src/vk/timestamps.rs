//! GPU timestamps: a query pool read back as milliseconds.

use std::sync::Arc;

use ash::vk;

use super::{Device, VkError};

/// A pool of timestamp queries, freed on drop.
pub struct Timestamps {
    device: Arc<Device>,
    pool: vk::QueryPool,
    count: u32,
}

impl Timestamps {
    /// A pool of `count` timestamps.
    pub fn new(device: &Arc<Device>, count: u32) -> Result<Self, VkError> {
        let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(count);
        // SAFETY: `device.raw` is alive; `info` is a local without pNext for timestamp queries, which need no
        // feature. `count` must be nonzero: the caller's (GpuTimer and the probe pass ask for 2), not checked
        // here.
        let pool = unsafe { device.raw.create_query_pool(&info, None) }?;
        Ok(Self { device: device.clone(), pool, count })
    }

    /// Records a reset of every query (outside a render pass).
    pub fn reset(&self, cmd: vk::CommandBuffer) {
        // SAFETY: `cmd` is a recording command buffer of this device (the callers pass `rec.cmd`; the type
        // cannot check it), outside any render pass (the renderer uses none); queries 0 to `count` - 1 are
        // exactly the pool's.
        unsafe { self.device.raw.cmd_reset_query_pool(cmd, self.pool, 0, self.count) };
    }

    /// Records timestamp `index` after all previous work has finished.
    pub fn write(&self, cmd: vk::CommandBuffer, index: u32) {
        // SAFETY: `cmd` as for `reset`, on a queue family with timestampValidBits > 0 (`GpuTimer::new` checks
        // this; other callers must); the caller has reset the pool earlier in the command buffer and passes
        // `index` < `count` (not checked here).
        unsafe { self.device.raw.cmd_write_timestamp(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, self.pool, index) };
    }

    /// Reads all timestamps (waiting for them) in nanoseconds.
    pub fn read_ns(&self) -> Result<Vec<f64>, VkError> {
        let mut ticks = vec![0u64; self.count as usize];
        // SAFETY: `self.pool` is live and owned by `self`; `ticks` holds `count` u64 values, which matches
        // TYPE_64 and the 8-byte stride ash passes. With WAIT the call blocks until the queries are
        // available, so every query must have been reset and written by a submitted command buffer: callers
        // read after `Commands::run` has waited for one that did (GpuTimer::run, the probe pass), which this
        // function cannot check.
        unsafe {
            self.device.raw.get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )?
        };
        let period = self.device.timestamp_period_ns();
        Ok(ticks.iter().map(|&t| t as f64 * period).collect())
    }
}

impl Drop for Timestamps {
    fn drop(&mut self) {
        // SAFETY: `self.pool` was created in `new` on `self.device` (a field, alive here) and is destroyed
        // once, here; no pending submission uses it, as `Commands::run` waits before returning.
        unsafe { self.device.raw.destroy_query_pool(self.pool, None) };
    }
}

/// Times submitted work on the GPU: a timestamp before and after it. Falls
/// back to the wall time of the (synchronous) submission on a queue without
/// timestamps.
pub struct GpuTimer {
    stamps: Option<Timestamps>,
}

impl GpuTimer {
    /// A timer on `device`'s queue.
    pub fn new(device: &Arc<Device>) -> Result<Self, VkError> {
        let stamps = if Self::available(device) { Some(Timestamps::new(device, 2)?) } else { None };
        Ok(Self { stamps })
    }

    /// True when `device`'s queue writes timestamps.
    pub fn available(device: &Device) -> bool {
        // SAFETY: `device.physical` is the physical device of `device.raw`, from the live `device.instance`.
        let families = unsafe { device.instance.raw.get_physical_device_queue_family_properties(device.physical) };
        families.get(device.queue_family as usize).is_some_and(|f| f.timestamp_valid_bits > 0)
    }

    /// True when times come from GPU timestamps (not wall clocks).
    pub fn is_gpu(&self) -> bool {
        self.stamps.is_some()
    }

    /// Records work with `record`, submits it, waits, and returns the
    /// result and the work's duration in seconds.
    pub fn run<R>(
        &self,
        cmds: &mut super::Commands,
        record: impl FnOnce(super::Recording<'_>) -> R,
    ) -> Result<(R, f64), VkError> {
        let start = std::time::Instant::now();
        let out = cmds.run(|rec| {
            if let Some(s) = &self.stamps {
                s.reset(rec.cmd);
                s.write(rec.cmd, 0);
            }
            let out = record(rec);
            if let Some(s) = &self.stamps {
                s.write(rec.cmd, 1);
            }
            out
        })?;
        let wall = start.elapsed().as_secs_f64();
        let seconds = match &self.stamps {
            Some(s) => {
                let ns = s.read_ns()?;
                (ns[1] - ns[0]).max(0.0) * 1e-9
            }
            None => wall,
        };
        Ok((out, seconds))
    }
}
