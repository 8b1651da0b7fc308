//! Buffers with their gpu-allocator memory; uploads go through a staging buffer when the memory
//! is not host-visible.
//!
//! Design decisions:
//! - The handle and its memory live in a shared `BufferShared`: a [`crate::DescriptorSet`] that
//!   points at the buffer keeps it alive, so dropping the `Buffer` first cannot leave the set
//!   pointing at a destroyed buffer. The last owner hands handle and memory to the device's
//!   retire queue, which destroys them once no submission that could use them is pending.
//! - Host access (mapped slices) belongs to the `Buffer` alone, through `&self` / `&mut self`;
//!   descriptor sets never touch the memory.
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext, VkError};
use crate::retire::Retired;
use ash::vk;
use gpu_allocator::vulkan::Allocation;
use gpu_allocator::MemoryLocation;
use std::ptr::NonNull;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct BufferDesc<'a> {
    pub name: &'a str,
    pub size: u64,
    pub usage: vk::BufferUsageFlags,
    pub location: MemoryLocation,
}

/// The handle and memory, shared by the [`Buffer`] and the descriptor sets that point at it.
pub(crate) struct BufferShared {
    pub(crate) raw: vk::Buffer,
    pub(crate) usage: vk::BufferUsageFlags,
    pub(crate) name: String,
    allocation: Option<Allocation>,
    device: Arc<DeviceShared>,
}

impl Drop for BufferShared {
    fn drop(&mut self) {
        self.device.retire(Retired::Buffer {
            raw: self.raw,
            allocation: self.allocation.take(),
        });
    }
}

/// A buffer and its memory.
pub struct Buffer {
    pub(crate) raw: vk::Buffer,
    pub size: u64,
    /// The mapping of host-visible memory: `size` bytes owned by `shared`'s allocation.
    mapped: Option<NonNull<u8>>,
    pub(crate) shared: Arc<BufferShared>,
}

// SAFETY: `mapped` points into the allocation that `shared` keeps alive; slices of it are only
// made through `&self` (shared) and `&mut self` (exclusive), so Rust's borrow rules on `Buffer`
// are the synchronization, exactly as for a `Vec<u8>`.
unsafe impl Send for Buffer {}
// SAFETY: as above; `&Buffer` only gives shared slices.
unsafe impl Sync for Buffer {}

impl Buffer {
    /// A buffer with `SHADER_DEVICE_ADDRESS` usage is refused ([`VkError::Unsupported`]) on a
    /// device without `bufferDeviceAddress` enabled.
    pub fn new(device: &Device, desc: &BufferDesc<'_>) -> Result<Self> {
        if desc
            .usage
            .contains(vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS)
            && !device.info.caps.buffer_device_address
        {
            return Err(VkError::Unsupported {
                device: device.info.name.clone(),
                what: "bufferDeviceAddress (buffers read by address)",
            });
        }
        let size = desc.size.max(4);
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: device is live; info is valid.
        let raw = unsafe { device.raw.create_buffer(&info, None) }.ctx("vkCreateBuffer")?;
        device.created(1);
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
                    // SAFETY: raw was never used by any command.
                    unsafe { device.raw.destroy_buffer(raw, None) };
                    device.destroyed(1);
                    return Err(e);
                }
            };
        device.set_name(raw, desc.name);
        let mapped = allocation
            .mapped_ptr()
            .filter(|_| allocation.size() >= size)
            .map(|p| p.cast::<u8>());
        Ok(Self {
            raw,
            size,
            mapped,
            shared: Arc::new(BufferShared {
                raw,
                usage: desc.usage,
                name: desc.name.to_owned(),
                allocation: Some(allocation),
                device: device.shared.clone(),
            }),
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
        if buffer.mapped.is_some() {
            buffer.write(0, data)?;
            return Ok(buffer);
        }
        let mut staging = Self::new(
            device,
            &BufferDesc {
                name: &format!("{name} (staging)"),
                size: data.len() as u64,
                usage: vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        staging.write(0, data)?;
        device.submit_once(|enc| enc.copy_buffer(&staging, &buffer))??;
        Ok(buffer)
    }

    pub fn name(&self) -> &str {
        &self.shared.name
    }

    pub fn size(&self) -> u64 {
        self.size
    }

    pub fn usage(&self) -> vk::BufferUsageFlags {
        self.shared.usage
    }

    /// The buffer's device address, for shaders that read it through a buffer reference
    /// (`GL_EXT_buffer_reference`): no descriptor, so no `maxStorageBufferRange`. The buffer
    /// must have `SHADER_DEVICE_ADDRESS` usage (a typed error otherwise). The address is valid
    /// while the buffer lives; the retire queue keeps it alive until the submissions that may
    /// use it complete.
    pub fn device_address(&self) -> Result<u64> {
        let needed = vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
        if !self.shared.usage.contains(needed) {
            return Err(VkError::Recording {
                command: "vkGetBufferDeviceAddress",
                problem: crate::error::RecordingError::BufferUsage {
                    buffer: self.shared.name.clone(),
                    needed,
                },
            });
        }
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.raw);
        // SAFETY: the buffer is live, bound to memory, and was created with
        // SHADER_DEVICE_ADDRESS usage, which `new` allows only with bufferDeviceAddress enabled
        // (gpu-allocator then allocates its memory with the DEVICE_ADDRESS flag).
        Ok(unsafe { self.shared.device.raw.get_buffer_device_address(&info) })
    }

    pub fn mapped(&self) -> Option<&[u8]> {
        let p = self.mapped?;
        // SAFETY: `p` maps `size` bytes of the allocation `shared` keeps alive; `&self` makes
        // the slice shared (see the Send/Sync note on `Buffer`).
        Some(unsafe { std::slice::from_raw_parts(p.as_ptr(), self.size as usize) })
    }

    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let p = self.mapped?;
        // SAFETY: as in `mapped`; `&mut self` makes the slice exclusive.
        Some(unsafe { std::slice::from_raw_parts_mut(p.as_ptr(), self.size as usize) })
    }

    /// Copies bytes into a host-visible buffer at `offset`.
    pub fn write(&mut self, offset: u64, data: &[u8]) -> Result<()> {
        let size = self.size;
        let name = self.shared.name.clone();
        let slice = self.mapped_mut().ok_or_else(|| VkError::NotHostVisible {
            buffer: name.clone(),
        })?;
        let start = usize::try_from(offset).unwrap_or(usize::MAX);
        let end = start
            .checked_add(data.len())
            .filter(|&e| e <= slice.len())
            .ok_or(VkError::OutOfBounds {
                object: name,
                what: "host write",
                offset,
                len: data.len() as u64,
                size,
            })?;
        slice[start..end].copy_from_slice(data);
        Ok(())
    }

    /// Reads a host-visible buffer as `T`s (the buffer's whole size, rounded down).
    pub fn read<T: bytemuck::Pod>(&self) -> Result<Vec<T>> {
        let slice = self.mapped().ok_or_else(|| VkError::NotHostVisible {
            buffer: self.shared.name.clone(),
        })?;
        let n = slice.len() / std::mem::size_of::<T>().max(1);
        let mut out = vec![T::zeroed(); n];
        bytemuck::cast_slice_mut::<T, u8>(&mut out)
            .copy_from_slice(&slice[..n * std::mem::size_of::<T>()]);
        Ok(out)
    }
}
