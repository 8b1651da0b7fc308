//! Indirect draw commands, and the bounds they promise.
//!
//! An indirect draw (`vkCmdDrawIndirect`, `vkCmdDrawIndexedIndirect`) reads its counts from a
//! buffer on the GPU, where the encoder cannot see them. So the commands live in an
//! [`IndirectDraws`], which knows the furthest vertex, index and instance any of its commands
//! reaches (its [`IndirectExtent`]), and the encoder checks that extent against the bound index
//! buffer and vertex buffers exactly as it checks a direct draw's ranges.
//!
//! Design decisions:
//! - **Commands written by the host are measured as they are written** ([`IndirectDraws::write`]):
//!   the extent is the maximum over the commands, so it can never be smaller than what the GPU
//!   reads.
//! - **Commands written by a shader carry a declared bound** ([`IndirectDraws::gpu_written`]):
//!   the shader that writes them must keep every command inside it (clamp, or write only counts
//!   it derived from tables checked against the same bound). That is the one place where a
//!   bound is promised rather than measured, and the constructor says so in its name.
//! - **No vertex offsets.** Tessera's index buffers index their vertex buffers directly (every
//!   index was checked against its vertex buffer when it was uploaded); a command with a
//!   non-zero `vertex_offset` would move those indices past what was checked, so it is refused.
//! - **Device features are respected, not assumed**: more than one draw per command needs
//!   `multiDrawIndirect`, a first instance other than 0 needs `drawIndirectFirstInstance`; both
//!   are refused as typed errors where the device lacks them.
use crate::buffer::{Buffer, BufferDesc};
use crate::device::Device;
use crate::error::{Result, VkError};
use ash::vk;
use bytemuck::{Pod, Zeroable};
use gpu_allocator::MemoryLocation;

/// `VkDrawIndirectCommand`, as the GPU reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct DrawCommand {
    pub vertex_count: u32,
    pub instance_count: u32,
    pub first_vertex: u32,
    pub first_instance: u32,
}

/// `VkDrawIndexedIndirectCommand`, as the GPU reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct DrawIndexedCommand {
    pub index_count: u32,
    pub instance_count: u32,
    pub first_index: u32,
    pub vertex_offset: i32,
    pub first_instance: u32,
}

/// Which command an [`IndirectDraws`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndirectKind {
    /// [`DrawCommand`]s: non-indexed.
    Draw,
    /// [`DrawIndexedCommand`]s: through the bound index buffer.
    DrawIndexed,
}

impl IndirectKind {
    /// Bytes of one command (the stride the draws use).
    pub fn stride(self) -> u32 {
        match self {
            IndirectKind::Draw => std::mem::size_of::<DrawCommand>() as u32,
            IndirectKind::DrawIndexed => std::mem::size_of::<DrawIndexedCommand>() as u32,
        }
    }
}

/// How far any command of an [`IndirectDraws`] reaches, as one past the last element read:
/// vertices (non-indexed commands), indices (indexed commands) and instances.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IndirectExtent {
    pub vertices: u32,
    pub indices: u32,
    pub instances: u32,
}

/// A buffer of indirect draw commands with the extent they can reach (see the module docs).
pub struct IndirectDraws {
    buffer: Buffer,
    kind: IndirectKind,
    draws: u32,
    extent: IndirectExtent,
    /// The device has `drawIndirectFirstInstance`.
    first_instance_ok: bool,
}

/// One past `first + count`, or an error naming the command when it overflows `u32`.
fn end_of(what: &'static str, draw: usize, first: u32, count: u32) -> Result<u32> {
    first.checked_add(count).ok_or(VkError::IndirectCommand {
        draw,
        problem: format!("{what} {first} + {count} overflows 32 bits"),
    })
}

impl IndirectDraws {
    /// Host-visible commands written once now (and rewritable by [`Self::write`]).
    pub fn host<C: IndirectCommand>(device: &Device, name: &str, commands: &[C]) -> Result<Self> {
        let mut out = Self::allocate(
            device,
            name,
            C::KIND,
            commands.len() as u32,
            vk::BufferUsageFlags::empty(),
            MemoryLocation::CpuToGpu,
        )?;
        out.write(commands)?;
        Ok(out)
    }

    /// Device-local room for `draws` commands that a shader writes (the buffer has storage
    /// usage), bounded by `extent`: the writing shader's contract is that no command reaches
    /// past it. Until the shader runs the commands are zero (draw nothing).
    pub fn gpu_written(
        device: &Device,
        name: &str,
        kind: IndirectKind,
        draws: u32,
        extent: IndirectExtent,
    ) -> Result<Self> {
        let mut out = Self::allocate(
            device,
            name,
            kind,
            draws,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        out.extent = extent;
        Ok(out)
    }

    fn allocate(
        device: &Device,
        name: &str,
        kind: IndirectKind,
        draws: u32,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        check_draw_count(device, draws)?;
        let buffer = Buffer::new(
            device,
            &BufferDesc {
                name,
                size: u64::from(draws.max(1)) * u64::from(kind.stride()),
                usage: usage | vk::BufferUsageFlags::INDIRECT_BUFFER,
                location,
            },
        )?;
        Ok(Self {
            buffer,
            kind,
            draws,
            extent: IndirectExtent::default(),
            first_instance_ok: device.info.caps.draw_indirect_first_instance,
        })
    }

    /// Rewrites host-visible commands (as many as the buffer was made for) and measures their
    /// extent. The GPU must be done with the previous commands (a frame slot's buffer).
    pub fn write<C: IndirectCommand>(&mut self, commands: &[C]) -> Result<()> {
        if C::KIND != self.kind || commands.len() != self.draws as usize {
            return Err(VkError::IndirectCommand {
                draw: commands.len(),
                problem: format!(
                    "{} {:?} commands written to a buffer of {} {:?} commands",
                    commands.len(),
                    C::KIND,
                    self.draws,
                    self.kind
                ),
            });
        }
        let mut extent = IndirectExtent::default();
        for (i, c) in commands.iter().enumerate() {
            c.extend(i, self.first_instance_ok, &mut extent)?;
        }
        self.buffer.write(0, bytemuck::cast_slice(commands))?;
        self.extent = extent;
        Ok(())
    }

    pub fn buffer(&self) -> &Buffer {
        &self.buffer
    }

    pub fn kind(&self) -> IndirectKind {
        self.kind
    }

    /// Draws the buffer holds (one indirect command executes them all).
    pub fn draws(&self) -> u32 {
        self.draws
    }

    pub fn extent(&self) -> IndirectExtent {
        self.extent
    }
}

/// The device executes `draws` draws from one indirect command.
fn check_draw_count(device: &Device, draws: u32) -> Result<()> {
    let caps = &device.info.caps;
    let max = if caps.multi_draw_indirect {
        caps.max_draw_indirect_count
    } else {
        1
    };
    if draws > max {
        return Err(VkError::IndirectCommand {
            draw: draws as usize,
            problem: format!(
                "{draws} draws in one indirect command; the device executes at most {max}{}",
                if caps.multi_draw_indirect {
                    ""
                } else {
                    " (no multiDrawIndirect)"
                }
            ),
        });
    }
    Ok(())
}

/// A command type an [`IndirectDraws`] holds: [`DrawCommand`] or [`DrawIndexedCommand`].
pub trait IndirectCommand: Pod {
    const KIND: IndirectKind;
    /// Grows `extent` to cover command `draw`, or refuses it.
    fn extend(
        &self,
        draw: usize,
        first_instance_ok: bool,
        extent: &mut IndirectExtent,
    ) -> Result<()>;
}

fn extend_instances(
    draw: usize,
    first_instance: u32,
    instance_count: u32,
    first_instance_ok: bool,
    extent: &mut IndirectExtent,
) -> Result<()> {
    if first_instance != 0 && !first_instance_ok {
        return Err(VkError::IndirectCommand {
            draw,
            problem: format!(
                "first instance {first_instance}: the device lacks drawIndirectFirstInstance"
            ),
        });
    }
    let end = end_of("instances", draw, first_instance, instance_count)?;
    extent.instances = extent.instances.max(end);
    Ok(())
}

impl IndirectCommand for DrawCommand {
    const KIND: IndirectKind = IndirectKind::Draw;
    fn extend(
        &self,
        draw: usize,
        first_instance_ok: bool,
        extent: &mut IndirectExtent,
    ) -> Result<()> {
        let end = end_of("vertices", draw, self.first_vertex, self.vertex_count)?;
        extent.vertices = extent.vertices.max(end);
        extend_instances(
            draw,
            self.first_instance,
            self.instance_count,
            first_instance_ok,
            extent,
        )
    }
}

impl IndirectCommand for DrawIndexedCommand {
    const KIND: IndirectKind = IndirectKind::DrawIndexed;
    fn extend(
        &self,
        draw: usize,
        first_instance_ok: bool,
        extent: &mut IndirectExtent,
    ) -> Result<()> {
        if self.vertex_offset != 0 {
            return Err(VkError::IndirectCommand {
                draw,
                problem: format!(
                    "vertex offset {}: indices address their vertex buffer directly",
                    self.vertex_offset
                ),
            });
        }
        let end = end_of("indices", draw, self.first_index, self.index_count)?;
        extent.indices = extent.indices.max(end);
        extend_instances(
            draw,
            self.first_instance,
            self.instance_count,
            first_instance_ok,
            extent,
        )
    }
}
