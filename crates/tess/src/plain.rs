//! A plain indexed triangle draw, no tessellation stage: how a mesh refined on the CPU (the
//! paper's comparison point, CPU subdivision to M^k) is drawn. Same `Frame` uniforms and
//! `shade.frag` as the tessellated techniques, so only the geometry path differs.
use crate::context::{set_vertex_input, Context};
use crate::error::{Result, TessError};
use crate::gpu::{DrawPush, Vertex};
use crate::shaders::{self, Stage, Variant};
use vk_core::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage};
use vk_core::{vk, Buffer, BufferDesc, Device, Encoder, MemoryLocation};

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
    if vertices.is_empty() || indices.is_empty() {
        return Err(TessError::Topology(topology::TopologyError::EmptyMesh {
            what: "a plain mesh needs vertices and triangles",
        }));
    }
    if !indices.chunks_exact(3).remainder().is_empty() {
        return Err(TessError::PartialTriangle {
            corners: indices.len(),
        });
    }
    let n = vertices.len() as u32;
    if let Some(&bad) = indices.iter().find(|&&i| i >= n) {
        return Err(TessError::IndexOutOfRange {
            what: "plain mesh index",
            index: bad as u64,
            len: n as u64,
        });
    }
    Ok(())
}

impl PlainMesh {
    /// Uploads once into device-local memory (a static refined mesh).
    pub fn upload(device: &Device, vertices: &[Vertex], indices: &[u32]) -> Result<Self> {
        check(vertices, indices)?;
        let vb = Buffer::with_data(
            device,
            "plain vertices",
            vk::BufferUsageFlags::VERTEX_BUFFER,
            bytemuck::cast_slice(vertices),
        )?;
        Self::with_vertex_buffer(device, vb, vertices, indices)
    }

    /// Vertices in host-visible memory, rewritten every frame by [`PlainMesh::write_vertices`]
    /// (an animated mesh re-subdivided on the CPU); the connectivity does not change.
    pub fn dynamic(device: &Device, vertices: &[Vertex], indices: &[u32]) -> Result<Self> {
        check(vertices, indices)?;
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
        Self::with_vertex_buffer(device, vb, vertices, indices)
    }

    /// The mesh around an uploaded vertex buffer (checked vertices and indices).
    fn with_vertex_buffer(
        device: &Device,
        vb: Buffer,
        vertices: &[Vertex],
        indices: &[u32],
    ) -> Result<Self> {
        let (bbox_min, bbox_max) = bbox(vertices);
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
            return Err(TessError::BasePositionCount {
                given: vertices.len(),
                expected: self.vertex_count as usize,
            });
        }
        self.vertices.write(0, bytemuck::cast_slice(vertices))?;
        Ok(())
    }

    pub fn triangles(&self) -> u64 {
        self.index_count as u64 / 3
    }
}

/// The non-tessellated pipeline; its set 0 is a [`Context`]'s frame set, so it sees the same
/// view as the tessellated techniques drawn through that context.
pub struct PlainRenderer {
    pipeline: Pipeline,
}

impl PlainRenderer {
    pub fn new(ctx: &Context) -> Result<Self> {
        let (color_format, depth_format) = ctx.formats();
        let mut desc = GraphicsPipelineDesc::new("plain triangles", color_format, depth_format);
        desc.stages = vec![
            ShaderStage::new(
                vk::ShaderStageFlags::VERTEX,
                shaders::spirv(Stage::PlainPlainVert, Variant::default())?,
            ),
            ShaderStage::new(
                vk::ShaderStageFlags::FRAGMENT,
                shaders::spirv(Stage::CommonShadeFrag, Variant::default())?,
            ),
        ];
        set_vertex_input(&mut desc);
        desc.set_layouts = vec![ctx.frame_set_layout().raw];
        desc.push_constant_bytes = std::mem::size_of::<DrawPush>() as u32;
        // The tessellated techniques' shaded pass uses this bias too: same raster work.
        desc.depth_bias = Some((1.0, 1.0));
        Ok(Self {
            pipeline: Pipeline::graphics(ctx.device(), &desc)?,
        })
    }

    /// Records the shaded draw of frame slot `slot` inside an active rendering scope; returns
    /// the triangles drawn.
    pub fn record<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        ctx: &'a Context,
        slot: usize,
        mesh: &'a PlainMesh,
    ) -> Result<u64> {
        enc.begin_label("plain triangles");
        enc.bind_pipeline(&self.pipeline);
        enc.bind_descriptor_sets(0, &[ctx.frame_set(slot)?])?;
        enc.push_constants(&DrawPush {
            mode: 0,
            first_patch: 0,
        })?;
        enc.bind_vertex_buffer(0, &mesh.vertices);
        enc.bind_index_buffer_u32(&mesh.indices);
        enc.draw_indexed(0..mesh.index_count)?;
        enc.end_label();
        Ok(mesh.triangles())
    }
}
