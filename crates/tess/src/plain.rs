//! A plain indexed triangle draw, no tessellation stage: how a mesh refined on the CPU (the
//! paper's comparison point, CPU subdivision to M^k) is drawn. Same `Frame` uniforms and
//! `shade.frag` as the tessellated techniques, so only the geometry path differs.
use crate::error::{Result, TessError};
use crate::gpu::{DrawPush, Vertex};
use crate::renderer::{frame_uniforms_for, set_vertex_input, DrawParams, FrameSets};
use crate::shaders::{spirv, Stage, Variant};
use vk_core::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage};
use vk_core::{vk, Buffer, BufferDesc, Device, MemoryLocation};

/// A triangle mesh on the GPU: vertices and a `u32` index list.
pub struct PlainMesh {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
    pub vertex_count: u32,
    pub bbox_min: [f32; 3],
    pub bbox_max: [f32; 3],
}

fn bbox(vertices: &[Vertex]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v.position[k]);
            hi[k] = hi[k].max(v.position[k]);
        }
    }
    (lo, hi)
}

fn check(vertices: &[Vertex], indices: &[u32]) -> Result<()> {
    if vertices.is_empty() || indices.is_empty() || !indices.chunks_exact(3).remainder().is_empty()
    {
        return Err(TessError::Invalid(format!(
            "a plain mesh needs vertices and whole triangles ({} vertices, {} indices)",
            vertices.len(),
            indices.len()
        )));
    }
    let n = vertices.len() as u32;
    if let Some(&bad) = indices.iter().find(|&&i| i >= n) {
        return Err(TessError::Invalid(format!(
            "index {bad} is out of range of {n} vertices"
        )));
    }
    Ok(())
}

impl PlainMesh {
    /// Uploads once into device-local memory (a static refined mesh).
    pub fn upload(device: &Device, vertices: &[Vertex], indices: &[u32]) -> Result<Self> {
        check(vertices, indices)?;
        let (bbox_min, bbox_max) = bbox(vertices);
        Ok(Self {
            vertices: Buffer::with_data(
                device,
                "plain vertices",
                vk::BufferUsageFlags::VERTEX_BUFFER,
                bytemuck::cast_slice(vertices),
            )?,
            indices: Buffer::with_data(
                device,
                "plain indices",
                vk::BufferUsageFlags::INDEX_BUFFER,
                bytemuck::cast_slice(indices),
            )?,
            index_count: indices.len() as u32,
            vertex_count: vertices.len() as u32,
            bbox_min,
            bbox_max,
        })
    }

    /// Vertices in host-visible memory, rewritten every frame by [`PlainMesh::write_vertices`]
    /// (an animated mesh re-subdivided on the CPU); the connectivity does not change.
    pub fn dynamic(device: &Device, vertices: &[Vertex], indices: &[u32]) -> Result<Self> {
        check(vertices, indices)?;
        let (bbox_min, bbox_max) = bbox(vertices);
        let mut vb = Buffer::new(
            device,
            &BufferDesc {
                name: "plain vertices (per-frame upload)",
                size: std::mem::size_of_val(vertices) as u64,
                usage: vk::BufferUsageFlags::VERTEX_BUFFER,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        vb.write(0, bytemuck::cast_slice(vertices))?;
        Ok(Self {
            vertices: vb,
            indices: Buffer::with_data(
                device,
                "plain indices",
                vk::BufferUsageFlags::INDEX_BUFFER,
                bytemuck::cast_slice(indices),
            )?,
            index_count: indices.len() as u32,
            vertex_count: vertices.len() as u32,
            bbox_min,
            bbox_max,
        })
    }

    /// Replaces the vertices of a [`PlainMesh::dynamic`] mesh; the GPU must be done with the
    /// previous frame (the bench waits for every frame).
    pub fn write_vertices(&mut self, vertices: &[Vertex]) -> Result<()> {
        if vertices.len() != self.vertex_count as usize {
            return Err(TessError::Invalid(format!(
                "{} vertices written to a mesh of {}",
                vertices.len(),
                self.vertex_count
            )));
        }
        self.vertices.write(0, bytemuck::cast_slice(vertices))?;
        Ok(())
    }

    pub fn triangles(&self) -> u64 {
        self.index_count as u64 / 3
    }
}

/// The non-tessellated pipeline with its own frame uniforms (one frame slot). Drop order:
/// pipeline, frame set.
pub struct PlainRenderer {
    pipeline: Pipeline,
    frame: FrameSets,
    device: Device,
}

impl PlainRenderer {
    pub fn new(
        device: &Device,
        color_format: vk::Format,
        depth_format: vk::Format,
    ) -> Result<Self> {
        let frame = FrameSets::new(device, "plain", 1)?;
        let mut desc = GraphicsPipelineDesc::new("plain triangles", color_format, depth_format);
        desc.stages = vec![
            ShaderStage::new(
                vk::ShaderStageFlags::VERTEX,
                spirv(Stage::PlainPlainVert, Variant::default())?,
            ),
            ShaderStage::new(
                vk::ShaderStageFlags::FRAGMENT,
                spirv(Stage::CommonShadeFrag, Variant::default())?,
            ),
        ];
        set_vertex_input(&mut desc);
        desc.set_layouts = vec![frame.layout()];
        desc.push_constant_bytes = std::mem::size_of::<DrawPush>() as u32;
        // The tessellated techniques' shaded pass uses this bias too: same raster work.
        desc.depth_bias = Some((1.0, 1.0));
        let pipeline = Pipeline::graphics(device, &desc)?;
        Ok(Self {
            pipeline,
            frame,
            device: device.clone(),
        })
    }

    /// Writes the frame uniforms for `params` (its level and Phong factor are unused here).
    pub fn update_uniforms(
        &mut self,
        mesh: &PlainMesh,
        params: &DrawParams,
        extent: vk::Extent2D,
    ) -> Result<()> {
        self.frame.write(
            0,
            &frame_uniforms_for((mesh.bbox_min, mesh.bbox_max), params, extent),
        )
    }

    /// Records the shaded draw inside an active rendering scope; returns the triangles drawn.
    pub fn record(&self, cmd: vk::CommandBuffer, mesh: &PlainMesh) -> Result<u64> {
        let device = &self.device;
        let set = self.frame.set(0)?;
        let push = DrawPush {
            mode: 0,
            first_patch: 0,
        };
        device.begin_label(cmd, "plain triangles");
        // SAFETY: cmd is recording inside a rendering scope; the pipeline, set and buffers are
        // owned by self and mesh, which outlive the submission (the bench waits for each frame);
        // the index count stays inside the index buffer (checked when it was built).
        unsafe {
            device
                .raw
                .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline.raw);
            device.raw.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.pipeline.layout,
                0,
                &[set],
                &[],
            );
            device.raw.cmd_push_constants(
                cmd,
                self.pipeline.layout,
                vk::ShaderStageFlags::ALL,
                0,
                bytemuck::bytes_of(&push),
            );
            device
                .raw
                .cmd_bind_vertex_buffers(cmd, 0, &[mesh.vertices.raw], &[0]);
            device
                .raw
                .cmd_bind_index_buffer(cmd, mesh.indices.raw, 0, vk::IndexType::UINT32);
            device
                .raw
                .cmd_draw_indexed(cmd, mesh.index_count, 1, 0, 0, 0);
        }
        device.end_label(cmd);
        Ok(mesh.triangles())
    }
}
