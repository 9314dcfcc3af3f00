//! Buffers that own their memory.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::{Device, Recording, VkError};

/// A buffer and its memory, freed on drop.
pub struct Buffer {
    device: Arc<Device>,
    /// The buffer handle.
    pub raw: vk::Buffer,
    allocation: Option<Allocation>,
    /// Size in bytes.
    pub size: u64,
}

impl Buffer {
    /// A storage buffer of `size` bytes in `location`, which transfers can
    /// also fill ([`Buffer::fill`]).
    pub fn storage(device: &Arc<Device>, name: &str, size: u64, location: MemoryLocation) -> Result<Self, VkError> {
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        Self::new(device, name, size, usage, location)
    }

    /// Creates a buffer of `size` bytes (at least 4) in `location`.
    pub fn new(
        device: &Arc<Device>,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self, VkError> {
        let size = size.max(4);
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: `device.raw` is alive (the Arc is held); `info` is a local without pNext: a nonzero size,
        // exclusive sharing, and SHADER_DEVICE_ADDRESS usage, which needs the bufferDeviceAddress feature
        // that `Device::create` enables.
        let raw = unsafe { device.raw.create_buffer(&info, None) }?;
        // SAFETY: `raw` was just created on this device and is not destroyed yet.
        let requirements = unsafe { device.raw.get_buffer_memory_requirements(raw) };
        let allocation = device.allocator.lock().expect("allocator lock").allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: `raw` was created above, has no memory bound and was never recorded into a command
                // buffer; it is not used after this.
                unsafe { device.raw.destroy_buffer(raw, None) };
                return Err(VkError::Allocation(format!("{name}: {e}")));
            }
        };
        // SAFETY: `allocation` was made by this device's allocator from `raw`'s own memory requirements, so
        // its memory type, size and offset alignment fit; `raw` has no memory bound yet.
        if let Err(e) = unsafe { device.raw.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) } {
            let _ = device.allocator.lock().expect("allocator lock").free(allocation);
            // SAFETY: binding failed, so `raw` is unbound and was never used; its allocation was freed just
            // above and the handle is not used after this.
            unsafe { device.raw.destroy_buffer(raw, None) };
            return Err(e.into());
        }
        Ok(Self { device: device.clone(), raw, allocation: Some(allocation), size })
    }

    /// A host-visible buffer holding `data`.
    pub fn with_data<T: bytemuck::Pod>(
        device: &Arc<Device>,
        name: &str,
        data: &[T],
        usage: vk::BufferUsageFlags,
    ) -> Result<Self, VkError> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let mut b = Self::new(device, name, bytes.len() as u64, usage, MemoryLocation::CpuToGpu)?;
        b.write(0, bytes);
        Ok(b)
    }

    /// The buffer's device address.
    pub fn device_address(&self) -> vk::DeviceAddress {
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.raw);
        // SAFETY: `self.raw` is owned by `self` (destroyed only in Drop), bound to memory (`Buffer::new`
        // returns only after binding) and created with SHADER_DEVICE_ADDRESS usage on a device with
        // bufferDeviceAddress enabled; `info` lives for the call.
        unsafe { self.device.raw.get_buffer_device_address(&info) }
    }

    fn mapped(&self) -> &[u8] {
        self.allocation.as_ref().and_then(|a| a.mapped_slice()).expect("buffer is not host visible")
    }

    /// The (host-visible) buffer's memory, to write in place.
    pub fn bytes_mut(&mut self) -> &mut [u8] {
        self.allocation.as_mut().and_then(|a| a.mapped_slice_mut()).expect("buffer is not host visible")
    }

    /// Records filling the whole buffer with the 32-bit word `word` (a
    /// transfer write: [`crate::vk::Access::TransferWrite`]). The buffer
    /// needs `TRANSFER_DST` usage, as [`Buffer::storage`] gives it.
    pub fn fill(&self, rec: Recording<'_>, word: u32) {
        // SAFETY: the buffer is alive while the submission runs (the caller
        // holds it across `Commands::run`, which waits).
        unsafe { rec.device.cmd_fill_buffer(rec.cmd, self.raw, 0, vk::WHOLE_SIZE, word) };
    }

    /// Records copying the whole buffer into `dst` (at least as large): a
    /// transfer read of this buffer and a transfer write of `dst`. This
    /// buffer needs `TRANSFER_SRC` usage and `dst` `TRANSFER_DST`.
    pub fn copy_to(&self, rec: Recording<'_>, dst: &Buffer) {
        assert!(dst.size >= self.size, "copy of {} bytes into a buffer of {}", self.size, dst.size);
        let region = [vk::BufferCopy::default().size(self.size)];
        // SAFETY: both buffers are alive while the submission runs (the
        // caller holds them across `Commands::run`, which waits), `dst` holds
        // the region, and the caller's barriers order the copy.
        unsafe { rec.device.cmd_copy_buffer(rec.cmd, self.raw, dst.raw, &region) };
    }

    /// Records writing the 32-bit `words` at byte `offset` (a multiple of 4)
    /// from the command buffer itself (`vkCmdUpdateBuffer`, at most 64 KiB:
    /// a transfer write, [`crate::vk::Access::TransferWrite`]). The buffer
    /// needs `TRANSFER_DST` usage.
    pub fn update(&self, rec: Recording<'_>, offset: u64, words: &[u32]) {
        let bytes: &[u8] = bytemuck::cast_slice(words);
        assert!(offset.is_multiple_of(4) && offset + bytes.len() as u64 <= self.size && bytes.len() <= 65536);
        // SAFETY: the buffer is alive while the submission runs (the caller holds it across
        // `Commands::run`, which waits); offset and size are multiples of 4 within the buffer, at most
        // 64 KiB, as vkCmdUpdateBuffer requires.
        unsafe { rec.device.cmd_update_buffer(rec.cmd, self.raw, offset, bytes) };
    }

    /// Records copying `size` bytes at `offset` of this buffer to the same
    /// offset of `dst` (a transfer read of this buffer, a transfer write of
    /// `dst`; `TRANSFER_SRC` and `TRANSFER_DST` usage).
    pub fn copy_range_to(&self, rec: Recording<'_>, dst: &Buffer, offset: u64, size: u64) {
        assert!(offset + size <= self.size && offset + size <= dst.size, "copy outside a buffer");
        let region = [vk::BufferCopy::default().src_offset(offset).dst_offset(offset).size(size)];
        // SAFETY: both buffers are alive while the submission runs (the caller holds them across
        // `Commands::run`, which waits); the region lies in both (checked above); the caller's barriers
        // order the copy.
        unsafe { rec.device.cmd_copy_buffer(rec.cmd, self.raw, dst.raw, &region) };
    }

    /// Copies `bytes` into the (host-visible) buffer at `offset`.
    pub fn write(&mut self, offset: usize, bytes: &[u8]) {
        self.bytes_mut()[offset..offset + bytes.len()].copy_from_slice(bytes);
    }

    /// Reads the (host-visible) buffer as a vector of `T`.
    pub fn read<T: bytemuck::Pod>(&self) -> Vec<T> {
        let bytes = self.mapped();
        let n = bytes.len() / std::mem::size_of::<T>();
        bytemuck::pod_collect_to_vec(&bytes[..n * std::mem::size_of::<T>()])
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if let Some(a) = self.allocation.take() {
            let _ = self.device.allocator.lock().map(|mut al| al.free(a));
        }
        // SAFETY: `self.raw` was created by `Buffer::new` on `self.device` and is destroyed once, here; the
        // device outlives it (`device` is a field, dropped after this body). No submission still uses it:
        // `Commands::run` waits on its fence before returning, and callers keep a buffer alive across the
        // `run` that records it. Its memory was freed just above, which Vulkan allows before the buffer is
        // destroyed.
        unsafe { self.device.raw.destroy_buffer(self.raw, None) };
    }
}
