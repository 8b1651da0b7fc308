//! Buffers with their gpu-allocator memory; uploads go through a staging buffer when the memory
//! is not host-visible.
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext, VkError};
use ash::vk;
use gpu_allocator::vulkan::Allocation;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct BufferDesc<'a> {
    pub name: &'a str,
    pub size: u64,
    pub usage: vk::BufferUsageFlags,
    pub location: MemoryLocation,
}

/// A buffer and its memory. Drop order: buffer handle, then the allocation is handed back.
pub struct Buffer {
    pub raw: vk::Buffer,
    pub size: u64,
    allocation: Option<Allocation>,
    name: String,
    device: Arc<DeviceShared>,
}

impl Buffer {
    pub fn new(device: &Device, desc: &BufferDesc<'_>) -> Result<Self> {
        let size = desc.size.max(4);
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: device is live; info is valid.
        let raw = unsafe { device.raw.create_buffer(&info, None) }.ctx("vkCreateBuffer")?;
        // SAFETY: raw was just created on this device.
        let requirements = unsafe { device.raw.get_buffer_memory_requirements(raw) };
        let bind = |memory, offset| {
            // SAFETY: raw is unbound; allocate_bound passes memory made for its requirements.
            unsafe { device.raw.bind_buffer_memory(raw, memory, offset) }.ctx("vkBindBufferMemory")
        };
        let allocation =
            match device.allocate_bound(desc.name, requirements, desc.location, true, bind) {
                Ok(a) => a,
                Err(e) => {
                    // SAFETY: raw is unused.
                    unsafe { device.raw.destroy_buffer(raw, None) };
                    return Err(e);
                }
            };
        device.set_name(raw, desc.name);
        Ok(Self {
            raw,
            size,
            allocation: Some(allocation),
            name: desc.name.to_owned(),
            device: device.shared.clone(),
        })
    }

    /// A device-local buffer filled with `data` (through staging when not host-visible).
    pub fn with_data(
        device: &Device,
        name: &str,
        usage: vk::BufferUsageFlags,
        data: &[u8],
    ) -> Result<Self> {
        let mut buffer = Self::new(
            device,
            &BufferDesc {
                name,
                size: data.len() as u64,
                usage: usage | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        if buffer.mapped_mut().is_some() {
            buffer.write(0, data)?;
            return Ok(buffer);
        }
        let staging = Self::new(
            device,
            &BufferDesc {
                name: &format!("{name} (staging)"),
                size: data.len() as u64,
                usage: vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        let mut staging = staging;
        staging.write(0, data)?;
        let size = data.len() as u64;
        device.one_shot(|cmd| {
            let region = [vk::BufferCopy::default().size(size.max(4))];
            // SAFETY: both buffers are live and large enough; cmd is recording.
            unsafe {
                device
                    .raw
                    .cmd_copy_buffer(cmd, staging.raw, buffer.raw, &region)
            };
        })?;
        Ok(buffer)
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn mapped(&self) -> Option<&[u8]> {
        self.allocation.as_ref()?.mapped_slice()
    }

    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        self.allocation.as_mut()?.mapped_slice_mut()
    }

    /// Copies bytes into a host-visible buffer at `offset`.
    pub fn write(&mut self, offset: u64, data: &[u8]) -> Result<()> {
        let name = self.name.clone();
        let slice = self
            .mapped_mut()
            .ok_or_else(|| VkError::Invalid(format!("buffer {name} is not host-visible")))?;
        let start = offset as usize;
        let end = start
            .checked_add(data.len())
            .filter(|&e| e <= slice.len())
            .ok_or_else(|| {
                VkError::Invalid(format!(
                    "write of {} bytes at {offset} overflows buffer {name}",
                    data.len()
                ))
            })?;
        slice[start..end].copy_from_slice(data);
        Ok(())
    }

    /// Reads a host-visible buffer as `T`s (the buffer's whole size, rounded down).
    pub fn read<T: bytemuck::Pod>(&self) -> Result<Vec<T>> {
        let slice = self
            .mapped()
            .ok_or_else(|| VkError::Invalid(format!("buffer {} is not host-visible", self.name)))?;
        let n = slice.len() / std::mem::size_of::<T>();
        let mut out = vec![T::zeroed(); n];
        bytemuck::cast_slice_mut::<T, u8>(&mut out)
            .copy_from_slice(&slice[..n * std::mem::size_of::<T>()]);
        Ok(out)
    }

    pub fn descriptor(&self) -> vk::DescriptorBufferInfo {
        vk::DescriptorBufferInfo::default()
            .buffer(self.raw)
            .offset(0)
            .range(vk::WHOLE_SIZE)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: owners keep buffers alive until the GPU finished with them (one-shot submits
        // wait; frame resources are dropped after a wait for their fence).
        unsafe { self.device.raw.destroy_buffer(self.raw, None) };
        if let Some(a) = self.allocation.take() {
            self.device.free(a);
        }
    }
}
