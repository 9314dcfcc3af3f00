//! Acceleration structures: bottom levels of procedural AABBs (one per
//! functional object, one AABB per cell) and a top level of instances.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::{Access, Buffer, Commands, Device, VkError};

/// An acceleration structure and the buffer that stores it.
// Release order: `Drop::drop` destroys `raw` before any field drops, so `buffer`, the structure's storage,
// outlives it.
pub struct AccelerationStructure {
    device: Arc<Device>,
    /// The handle.
    pub raw: vk::AccelerationStructureKHR,
    /// Storage.
    pub buffer: Buffer,
    /// Device address (for TLAS instances).
    pub address: vk::DeviceAddress,
}

/// One instance of a bottom level in the top level.
pub struct Instance<'a> {
    /// The bottom level.
    pub blas: &'a AccelerationStructure,
    /// Row-major 3x4 object-to-world matrix.
    pub transform: [f32; 12],
    /// 24-bit custom index (read in shaders as the instance's custom index).
    pub custom_index: u32,
}

fn align_up(v: u64, a: u64) -> u64 {
    v.div_ceil(a) * a
}

impl AccelerationStructure {
    /// A buffer holding a build's input (boxes or instances), readable by the build.
    fn build_input(device: &Arc<Device>, name: &str, bytes: &[u8]) -> Result<Buffer, VkError> {
        Buffer::with_data(device, name, bytes, vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR)
    }

    fn build(
        device: &Arc<Device>,
        cmds: &mut Commands,
        ty: vk::AccelerationStructureTypeKHR,
        geometry: vk::AccelerationStructureGeometryKHR<'_>,
        primitive_count: u32,
        name: &str,
    ) -> Result<Self, VkError> {
        let geometries = [geometry];
        let mut build_info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(ty)
            .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geometries);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        // SAFETY: `device.accel` was loaded for `device.raw`, which enabled VK_KHR_acceleration_structure and
        // its accelerationStructure feature (required of every device); `build_info` -> `geometries` and the
        // count slice (one maximum primitive count per geometry) are locals alive until the call returns. The
        // query ignores the geometry's device addresses.
        unsafe {
            device.accel.get_acceleration_structure_build_sizes(
                vk::AccelerationStructureBuildTypeKHR::DEVICE,
                &build_info,
                &[primitive_count],
                &mut sizes,
            )
        };
        let buffer = Buffer::new(
            device,
            name,
            sizes.acceleration_structure_size,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR,
            MemoryLocation::GpuOnly,
        )?;
        let create = vk::AccelerationStructureCreateInfoKHR::default()
            .buffer(buffer.raw)
            .size(sizes.acceleration_structure_size)
            .ty(ty);
        // SAFETY: `buffer` is live, bound to memory and created with ACCELERATION_STRUCTURE_STORAGE_KHR usage
        // and at least `acceleration_structure_size` bytes; offset 0 is a multiple of 256; `create` lives
        // until the call returns. `buffer` moves into `this`, so it outlives the structure (see the struct).
        let raw = unsafe { device.accel.create_acceleration_structure(&create, None) }?;
        let this = Self {
            device: device.clone(),
            raw,
            // SAFETY: `raw` was just created on this device, backed by a bound buffer; the info is a
            // temporary alive for the call.
            address: unsafe {
                device.accel.get_acceleration_structure_device_address(
                    &vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(raw),
                )
            },
            buffer,
        };

        let align = device.accel_properties.min_scratch_offset_alignment.max(1) as u64;
        let scratch = Buffer::storage(device, "scratch", sizes.build_scratch_size + align, MemoryLocation::GpuOnly)?;
        let scratch_address = align_up(scratch.device_address(), align);
        build_info = build_info
            .dst_acceleration_structure(raw)
            .scratch_data(vk::DeviceOrHostAddressKHR { device_address: scratch_address });
        let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(primitive_count)];
        // The build's inputs are host writes, which the submission makes
        // visible; what reads the structure next is a build (a TLAS over
        // this BLAS) or a trace in any stage the device runs.
        let mut next = vec![Access::AccelerationStructureBuild];
        next.extend(device.in_every_stage(Access::Trace));
        cmds.run(|rec| {
            // SAFETY: the build's structures and scratch buffer live until
            // the submission has finished (run waits on its fence).
            unsafe { device.accel.cmd_build_acceleration_structures(rec.cmd, &[build_info], &[&range]) };
            rec.barrier(&[Access::AccelerationStructureBuild], &next);
        })?;
        Ok(this)
    }

    /// A bottom level holding one procedural AABB per `[min, max]` box.
    pub fn bottom_level_aabbs(device: &Arc<Device>, cmds: &mut Commands, aabbs: &[[f32; 6]]) -> Result<Self, VkError> {
        let positions: Vec<vk::AabbPositionsKHR> = aabbs
            .iter()
            .map(|b| vk::AabbPositionsKHR {
                min_x: b[0],
                min_y: b[1],
                min_z: b[2],
                max_x: b[3],
                max_y: b[4],
                max_z: b[5],
            })
            .collect();
        // SAFETY: `positions` is a live Vec of `AabbPositionsKHR` (repr(C), six f32, no padding), so all
        // `size_of_val` bytes from its pointer are initialised, and u8 needs no alignment; `bytes` is used
        // only while `positions` lives (copied by `with_data` below).
        let bytes = unsafe {
            std::slice::from_raw_parts(positions.as_ptr() as *const u8, std::mem::size_of_val(positions.as_slice()))
        };
        let input = Self::build_input(device, "blas aabbs", bytes)?;
        let data = vk::AccelerationStructureGeometryAabbsDataKHR::default()
            .data(vk::DeviceOrHostAddressConstKHR { device_address: input.device_address() })
            .stride(std::mem::size_of::<vk::AabbPositionsKHR>() as u64);
        let geometry = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::AABBS)
            .flags(vk::GeometryFlagsKHR::OPAQUE)
            .geometry(vk::AccelerationStructureGeometryDataKHR { aabbs: data });
        Self::build(device, cmds, vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, geometry, aabbs.len() as u32, "blas")
    }

    /// A top level over `instances`.
    pub fn top_level(device: &Arc<Device>, cmds: &mut Commands, instances: &[Instance<'_>]) -> Result<Self, VkError> {
        let raw_instances: Vec<vk::AccelerationStructureInstanceKHR> = instances
            .iter()
            .map(|i| vk::AccelerationStructureInstanceKHR {
                transform: vk::TransformMatrixKHR { matrix: i.transform },
                instance_custom_index_and_mask: vk::Packed24_8::new(i.custom_index, 0xff),
                instance_shader_binding_table_record_offset_and_flags: vk::Packed24_8::new(
                    0,
                    vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE.as_raw() as u8,
                ),
                acceleration_structure_reference: vk::AccelerationStructureReferenceKHR {
                    device_handle: i.blas.address,
                },
            })
            .collect();
        // SAFETY: `raw_instances` is a live Vec of `AccelerationStructureInstanceKHR`, repr(C) and 64 bytes
        // without padding (a 48-byte matrix, two packed u32 fields, an 8-byte union whose variants both fill
        // it), so all its bytes are initialised; `bytes` is used only while `raw_instances` lives.
        let bytes = unsafe {
            std::slice::from_raw_parts(
                raw_instances.as_ptr() as *const u8,
                std::mem::size_of_val(raw_instances.as_slice()),
            )
        };
        let input = Self::build_input(device, "tlas instances", bytes)?;
        let data = vk::AccelerationStructureGeometryInstancesDataKHR::default()
            .array_of_pointers(false)
            .data(vk::DeviceOrHostAddressConstKHR { device_address: input.device_address() });
        let geometry = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::INSTANCES)
            .geometry(vk::AccelerationStructureGeometryDataKHR { instances: data });
        Self::build(device, cmds, vk::AccelerationStructureTypeKHR::TOP_LEVEL, geometry, instances.len() as u32, "tlas")
    }
}

impl Drop for AccelerationStructure {
    fn drop(&mut self) {
        // SAFETY: `self.raw` was created in `build` on `self.device` (a field, alive here) and is destroyed
        // once, here, while its storage `buffer` still exists (fields drop after this body); no pending build
        // or trace uses it, as `Commands::run` waits before returning. A top level built over this bottom
        // level must not be traced afterwards: that is the caller's to ensure (`Instance` borrows the bottom
        // level only for the build).
        unsafe { self.device.accel.destroy_acceleration_structure(self.raw, None) };
    }
}
