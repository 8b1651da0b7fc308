//! Descriptor-set layouts, pools, and typed descriptor sets.
//!
//! Design decisions:
//! - A [`DescriptorSet`] is owned and typed: it keeps its pool, its layout and every buffer and
//!   texture written into it alive (Vulkan forbids destroying any of them while the set may be
//!   used, and updating a set whose layout is gone), and is freed with its pool once the last set
//!   and the pool handle are dropped.
//! - [`DescriptorSet::write_buffer_range`] (and [`DescriptorSet::write_buffer`], the whole
//!   buffer) checks what Vulkan would otherwise leave to the caller: the binding exists with that
//!   type, the buffer has the matching usage, the range lies inside the buffer at an aligned
//!   offset and fits the device's `max*BufferRange` (as capped by
//!   [`crate::DeviceDesc::storage_buffer_range_cap`]), and the set is not in use (bound in a
//!   recording that was not submitted: refused; used by submissions still pending: waited for).
//!   A range beyond the limit is a typed error, never a silent overrun: callers with larger
//!   buffers bind windows of them (`tess`'s techniques split their draws so).
//! - [`DescriptorSet::write_texture`] writes a combined image sampler (the texture's view and
//!   sampler, in its resting layout SHADER_READ_ONLY_OPTIMAL) under the same in-use rules.
use crate::buffer::{Buffer, BufferShared};
use crate::device::{Device, DeviceShared};
use crate::error::{DescriptorError, Result, VkContext, VkError};
use crate::retire::Retired;
use crate::texture::{Texture, TextureShared};
use ash::vk;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// One binding of a set: (binding index, type, stages).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BindingDesc {
    pub binding: u32,
    pub ty: vk::DescriptorType,
    pub stages: vk::ShaderStageFlags,
}

struct LayoutShared {
    raw: vk::DescriptorSetLayout,
    device: Arc<DeviceShared>,
}

impl Drop for LayoutShared {
    fn drop(&mut self) {
        self.device.retire(Retired::DescriptorSetLayout(self.raw));
    }
}

/// A descriptor-set layout; clones share the one handle (destroyed with the last of them and
/// of the sets allocated with it), so an owner may hand it to a surface that allocates sets
/// later.
#[derive(Clone)]
pub struct DescriptorSetLayout {
    pub raw: vk::DescriptorSetLayout,
    pub bindings: Vec<BindingDesc>,
    shared: Arc<LayoutShared>,
}

impl DescriptorSetLayout {
    pub fn new(device: &Device, name: &str, bindings: &[BindingDesc]) -> Result<Self> {
        let vk_bindings: Vec<_> = bindings
            .iter()
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(b.ty)
                    .descriptor_count(1)
                    .stage_flags(b.stages)
            })
            .collect();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&vk_bindings);
        // SAFETY: device live; the info references live locals.
        let raw = unsafe { device.raw.create_descriptor_set_layout(&info, None) }
            .ctx("vkCreateDescriptorSetLayout")?;
        device.created(1);
        device.set_name(raw, name);
        Ok(Self {
            raw,
            bindings: bindings.to_vec(),
            shared: Arc::new(LayoutShared {
                raw,
                device: device.shared.clone(),
            }),
        })
    }
}

struct PoolShared {
    raw: vk::DescriptorPool,
    name: String,
    /// Allocation from a pool is externally synchronized.
    lock: Mutex<()>,
    device: Arc<DeviceShared>,
}

impl Drop for PoolShared {
    fn drop(&mut self) {
        self.device.retire(Retired::DescriptorPool(self.raw));
    }
}

/// A pool sized for `max_sets` sets of a layout; its sets are freed with it.
pub struct DescriptorPool {
    pub(crate) raw: vk::DescriptorPool,
    shared: Arc<PoolShared>,
    /// Sets handed out so far, for their names.
    allocated: AtomicU32,
}

impl DescriptorPool {
    pub fn new(
        device: &Device,
        name: &str,
        layout: &DescriptorSetLayout,
        max_sets: u32,
    ) -> Result<Self> {
        let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
        for b in &layout.bindings {
            match sizes.iter_mut().find(|s| s.ty == b.ty) {
                Some(s) => s.descriptor_count += max_sets,
                None => sizes.push(vk::DescriptorPoolSize {
                    ty: b.ty,
                    descriptor_count: max_sets,
                }),
            }
        }
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(max_sets)
            .pool_sizes(&sizes);
        // SAFETY: device live; the info references live locals.
        let raw = unsafe { device.raw.create_descriptor_pool(&info, None) }
            .ctx("vkCreateDescriptorPool")?;
        device.created(1);
        device.set_name(raw, name);
        Ok(Self {
            raw,
            shared: Arc::new(PoolShared {
                raw,
                name: name.to_owned(),
                lock: Mutex::new(()),
                device: device.shared.clone(),
            }),
            allocated: AtomicU32::new(0),
        })
    }

    fn allocate_raw(&self, layout: &DescriptorSetLayout) -> Result<vk::DescriptorSet> {
        let layouts = [layout.raw];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.raw)
            .set_layouts(&layouts);
        let _guard = self.shared.lock.lock().map_err(|_| VkError::LockPoisoned {
            what: "descriptor pool",
        })?;
        // SAFETY: pool and layout are live and from this device; allocations from the pool are
        // serialized by its lock.
        Ok(
            unsafe { self.shared.device.raw.allocate_descriptor_sets(&info) }
                .ctx("vkAllocateDescriptorSets")?[0],
        )
    }

    /// A set of `layout`, owned; the pool lives as long as any of its sets.
    pub fn allocate_set(&self, layout: &DescriptorSetLayout) -> Result<DescriptorSet> {
        let raw = self.allocate_raw(layout)?;
        let n = self.allocated.fetch_add(1, Ordering::Relaxed);
        let name = format!("{} set {n}", self.shared.name);
        self.shared.device.set_name(raw, &name);
        Ok(DescriptorSet {
            raw,
            name,
            bindings: layout.bindings.clone(),
            written: Mutex::new(vec![None; layout.bindings.len()]),
            recordings: AtomicU32::new(0),
            last_use: AtomicU64::new(0),
            _layout: layout.shared.clone(),
            pool: self.shared.clone(),
        })
    }
}

/// What a binding points at, held only so the set keeps it alive.
#[derive(Clone)]
#[expect(dead_code, reason = "the handles are held for their Drop, never read")]
enum Written {
    Buffer(Arc<BufferShared>),
    Texture(Arc<TextureShared>),
}

/// A descriptor set from a [`DescriptorPool`]: owned, typed by its layout's bindings.
pub struct DescriptorSet {
    pub(crate) raw: vk::DescriptorSet,
    name: String,
    bindings: Vec<BindingDesc>,
    /// What was written into each binding (in `bindings` order), kept alive by the set.
    written: Mutex<Vec<Option<Written>>>,
    /// Unsubmitted recordings that bound the set (each bind counts once).
    recordings: AtomicU32,
    /// The newest submission that used the set.
    last_use: AtomicU64,
    /// Drop order: the set's references, then its layout and pool (freed with the pool).
    _layout: Arc<LayoutShared>,
    pool: Arc<PoolShared>,
}

impl DescriptorSet {
    pub fn name(&self) -> &str {
        &self.name
    }

    pub(crate) fn layout_raw(&self) -> vk::DescriptorSetLayout {
        self._layout.raw
    }

    /// Counts a recording in, so writes are refused until it is submitted or abandoned; or the
    /// first binding never written (then nothing is counted). Under the write lock, so a write
    /// either completes before the recording binds the set or sees it counted.
    pub(crate) fn enter_recording(&self) -> std::result::Result<(), u32> {
        let Ok(written) = self.written.lock() else {
            return Err(self.bindings.first().map_or(0, |b| b.binding));
        };
        if let Some((b, _)) = self
            .bindings
            .iter()
            .zip(written.iter())
            .find(|(_, w)| w.is_none())
        {
            return Err(b.binding);
        }
        self.recordings.fetch_add(1, Ordering::SeqCst);
        Ok(())
    }

    pub(crate) fn leave_recording(&self) {
        self.recordings.fetch_sub(1, Ordering::SeqCst);
    }

    pub(crate) fn used_by(&self, serial: u64) {
        self.last_use.fetch_max(serial, Ordering::SeqCst);
    }

    /// Points `binding` at the whole of `buffer`: [`Self::write_buffer_range`] over all of it.
    pub fn write_buffer(
        &self,
        binding: u32,
        ty: vk::DescriptorType,
        buffer: &Buffer,
    ) -> Result<()> {
        self.write_buffer_range(binding, ty, buffer, 0, buffer.size())
    }

    /// The layout's slot of `binding`, which must be of type `ty`.
    fn slot(&self, binding: u32, ty: vk::DescriptorType) -> Result<usize> {
        let fail = |problem| VkError::Descriptor {
            set: self.name.clone(),
            binding,
            problem,
        };
        let slot = self
            .bindings
            .iter()
            .position(|b| b.binding == binding)
            .ok_or_else(|| fail(DescriptorError::NoSuchBinding))?;
        let layout = self.bindings[slot].ty;
        if layout != ty {
            return Err(fail(DescriptorError::Type { layout, given: ty }));
        }
        Ok(slot)
    }

    /// Points `binding` at `range` bytes of `buffer` from `offset`; the set then keeps the buffer
    /// alive. Typed errors: no such binding or another type, the buffer lacks the usage, the
    /// range is empty or leaves the buffer, the offset is not a multiple of the device's
    /// alignment (storage: `minStorageBufferOffsetAlignment`; uniform: 256, the largest the
    /// spec allows), or the range exceeds `maxStorageBufferRange` / `maxUniformBufferRange`.
    /// Refused while the set is bound in an unsubmitted recording; waits for submissions that
    /// used it.
    pub fn write_buffer_range(
        &self,
        binding: u32,
        ty: vk::DescriptorType,
        buffer: &Buffer,
        offset: u64,
        range: u64,
    ) -> Result<()> {
        let fail = |problem| VkError::Descriptor {
            set: self.name.clone(),
            binding,
            problem,
        };
        let device = &self.pool.device;
        let slot = self.slot(binding, ty)?;
        let caps = &device.info.caps;
        let (usage, max, alignment) = match ty {
            vk::DescriptorType::UNIFORM_BUFFER => (
                vk::BufferUsageFlags::UNIFORM_BUFFER,
                caps.max_uniform_buffer_range,
                256,
            ),
            vk::DescriptorType::STORAGE_BUFFER => (
                vk::BufferUsageFlags::STORAGE_BUFFER,
                caps.max_storage_buffer_range,
                caps.min_storage_buffer_offset_alignment,
            ),
            other => return Err(fail(DescriptorError::UnsupportedType(other))),
        };
        if !buffer.usage().contains(usage) {
            return Err(fail(DescriptorError::Usage {
                buffer: buffer.name().to_owned(),
                needed: usage,
            }));
        }
        let inside = matches!(offset.checked_add(range), Some(end) if end <= buffer.size());
        if range == 0 || !inside {
            return Err(fail(DescriptorError::Window {
                buffer: buffer.name().to_owned(),
                offset,
                range,
                size: buffer.size(),
            }));
        }
        if !offset.is_multiple_of(alignment.max(1)) {
            return Err(fail(DescriptorError::Offset {
                buffer: buffer.name().to_owned(),
                offset,
                alignment,
            }));
        }
        if range > max as u64 {
            return Err(fail(DescriptorError::Range {
                buffer: buffer.name().to_owned(),
                size: range,
                max: max as u64,
            }));
        }
        let mut written = self.lock_for_update(binding)?;
        let info = [vk::DescriptorBufferInfo::default()
            .buffer(buffer.raw)
            .offset(offset)
            .range(range)];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.raw)
            .dst_binding(binding)
            .descriptor_type(ty)
            .buffer_info(&info);
        // SAFETY: the binding exists with this type; the buffer has the usage; the range lies
        // inside it at an aligned offset and fits the device's limit; the set's layout is alive
        // (held); no recording holds the set and every submission that used it completed
        // (lock_for_update); updates of this set are serialized by `written`'s lock. The buffer
        // is kept alive below for as long as the set.
        unsafe { device.raw.update_descriptor_sets(&[write], &[]) };
        written[slot] = Some(Written::Buffer(buffer.shared.clone()));
        Ok(())
    }

    /// Points `binding` (a COMBINED_IMAGE_SAMPLER) at `texture`'s view and sampler; the set then
    /// keeps the texture alive. Typed errors: no such binding or another type. Refused while the
    /// set is bound in an unsubmitted recording; waits for submissions that used it.
    pub fn write_texture(&self, binding: u32, texture: &Texture) -> Result<()> {
        const TY: vk::DescriptorType = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
        let slot = self.slot(binding, TY)?;
        let mut written = self.lock_for_update(binding)?;
        let shared = &texture.shared;
        let info = [vk::DescriptorImageInfo::default()
            .sampler(shared.sampler)
            .image_view(shared.image.view)
            .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(self.raw)
            .dst_binding(binding)
            .descriptor_type(TY)
            .image_info(&info);
        // SAFETY: the binding exists with this type; the view (of a SAMPLED image) and sampler
        // are live objects of this device and the image rests in SHADER_READ_ONLY_OPTIMAL
        // (crate::texture); the set's layout is alive (held); no recording holds the set and
        // every submission that used it completed (lock_for_update); updates of this set are
        // serialized by `written`'s lock. The texture is kept alive below for as long as the set.
        unsafe { self.pool.device.raw.update_descriptor_sets(&[write], &[]) };
        written[slot] = Some(Written::Texture(shared.clone()));
        Ok(())
    }

    /// Locks the written references for an update of `binding`: refused while a recording holds
    /// the set, after waiting for the submissions that used it.
    fn lock_for_update(&self, binding: u32) -> Result<MutexGuard<'_, Vec<Option<Written>>>> {
        let written = self.written.lock().map_err(|_| VkError::LockPoisoned {
            what: "descriptor set",
        })?;
        // Checked under the lock: the encoder counts itself in before recording the bind, and a
        // set already counted in is never updated (that would invalidate the recording).
        if self.recordings.load(Ordering::SeqCst) > 0 {
            return Err(VkError::Descriptor {
                set: self.name.clone(),
                binding,
                problem: DescriptorError::InUse,
            });
        }
        self.pool
            .device
            .wait_serial(self.last_use.load(Ordering::SeqCst))?;
        Ok(written)
    }
}
