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
        let pool = unsafe { device.raw.create_query_pool(&info, None) }?;
        Ok(Self { device: device.clone(), pool, count })
    }

    /// Records a reset of every query (outside a render pass).
    pub fn reset(&self, cmd: vk::CommandBuffer) {
        unsafe { self.device.raw.cmd_reset_query_pool(cmd, self.pool, 0, self.count) };
    }

    /// Records timestamp `index` after all previous work has finished.
    pub fn write(&self, cmd: vk::CommandBuffer, index: u32) {
        unsafe { self.device.raw.cmd_write_timestamp(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, self.pool, index) };
    }

    /// Reads all timestamps (waiting for them) in nanoseconds.
    pub fn read_ns(&self) -> Result<Vec<f64>, VkError> {
        let mut ticks = vec![0u64; self.count as usize];
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
        unsafe { self.device.raw.destroy_query_pool(self.pool, None) };
    }
}
