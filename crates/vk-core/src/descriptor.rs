//! Descriptor-set layouts and a small pool that owns the sets it hands out.
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext};
use ash::vk;
use std::sync::Arc;

/// One binding of a set: (binding index, type, stages).
#[derive(Clone, Copy, Debug)]
pub struct BindingDesc {
    pub binding: u32,
    pub ty: vk::DescriptorType,
    pub stages: vk::ShaderStageFlags,
}

pub struct DescriptorSetLayout {
    pub raw: vk::DescriptorSetLayout,
    pub bindings: Vec<BindingDesc>,
    device: Arc<DeviceShared>,
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
        // SAFETY: device live.
        let raw = unsafe { device.raw.create_descriptor_set_layout(&info, None) }
            .ctx("vkCreateDescriptorSetLayout")?;
        device.set_name(raw, name);
        Ok(Self {
            raw,
            bindings: bindings.to_vec(),
            device: device.shared.clone(),
        })
    }
}

impl Drop for DescriptorSetLayout {
    fn drop(&mut self) {
        // SAFETY: pipelines using the layout were created already; layouts may be destroyed then.
        unsafe {
            self.device
                .raw
                .destroy_descriptor_set_layout(self.raw, None)
        };
    }
}

/// A pool sized for `max_sets` sets of a layout; freeing the pool frees its sets.
pub struct DescriptorPool {
    pub raw: vk::DescriptorPool,
    device: Arc<DeviceShared>,
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
        // SAFETY: device live.
        let raw = unsafe { device.raw.create_descriptor_pool(&info, None) }
            .ctx("vkCreateDescriptorPool")?;
        device.set_name(raw, name);
        Ok(Self {
            raw,
            device: device.shared.clone(),
        })
    }

    pub fn allocate(&self, layout: &DescriptorSetLayout) -> Result<vk::DescriptorSet> {
        let layouts = [layout.raw];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.raw)
            .set_layouts(&layouts);
        // SAFETY: pool and layout are live and from this device.
        Ok(unsafe { self.device.raw.allocate_descriptor_sets(&info) }
            .ctx("vkAllocateDescriptorSets")?[0])
    }

    /// Points each listed binding of `set` at a whole buffer.
    pub fn write_buffers(
        &self,
        set: vk::DescriptorSet,
        writes: &[(u32, vk::DescriptorType, vk::DescriptorBufferInfo)],
    ) {
        let infos: Vec<[vk::DescriptorBufferInfo; 1]> = writes.iter().map(|w| [w.2]).collect();
        let vk_writes: Vec<_> = writes
            .iter()
            .zip(&infos)
            .map(|(w, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(w.0)
                    .descriptor_type(w.1)
                    .buffer_info(info)
            })
            .collect();
        // SAFETY: the set is not in use by pending command buffers when updated.
        unsafe { self.device.raw.update_descriptor_sets(&vk_writes, &[]) };
    }
}

impl Drop for DescriptorPool {
    fn drop(&mut self) {
        // SAFETY: owners drop pools after the GPU finished using their sets.
        unsafe { self.device.raw.destroy_descriptor_pool(self.raw, None) };
    }
}
