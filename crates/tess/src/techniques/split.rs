//! Non-manifold meshes for the subdivision techniques: each is built on the mesh's manifold
//! split ([`ManifoldSplit`]: the same faces and corners, every non-manifold vertex cut into one
//! copy per fan of faces, OpenSubdiv's rules carried as sharpness tags), and [`SplitInput`]
//! presents it to callers in the input's terms.
//!
//! Why one wrapper rather than each technique splitting: a technique only ever sees a manifold
//! control mesh (its patch builders, tables and stencils need one), and what differs for a
//! non-manifold input is the same for all of them: the base positions an animation hands in
//! are the input's (each copy follows its source), and the base mesh callers evaluate and
//! classify against is the input. Face numbers and face domains are the input's already, so
//! [`Technique::face_point`] needs no translation.
use crate::capture::FacePoint;
use crate::error::{Result, TessError};
use crate::technique::{
    DeviceAllocation, DrawCounts, FrameParams, Pass, PatchArray, PatchPipeline, PatchType,
    Technique, TechniqueId,
};
use crate::techniques::{BuildOptions, Built, TechniqueInfo};
use crate::Context;
use topology::mesh::manifold::ManifoldSplit;
use topology::ControlMesh;
use vk_core::descriptor::BindingDesc;
use vk_core::{DescriptorSet, Encoder};

/// Builds `info`'s technique for `mesh`: as given when manifold, else on its manifold split,
/// wrapped in a [`SplitInput`], with the split's summary among the notes.
pub fn build_split(
    ctx: &mut Context,
    info: &TechniqueInfo,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    if info.scheme == Some(topology::Scheme::DooSabin) {
        topology::refine::check_doo_sabin_tags(mesh).map_err(|e| TessError::Mesh {
            name: options.name.clone(),
            source: e.into(),
        })?;
    }
    let split = ManifoldSplit::of(mesh).map_err(|e| TessError::Mesh {
        name: options.name.clone(),
        source: e.into(),
    })?;
    if split.is_identity() {
        return (info.build)(ctx, mesh, options);
    }
    let built = (info.build)(ctx, &split.mesh, options)?;
    let mut notes = vec![format!("{}: {}", options.name, split.report.summary())];
    notes.extend(built.notes);
    Ok(Built {
        technique: Box::new(SplitInput {
            inner: built.technique,
            input: mesh.clone(),
            split,
        }),
        notes,
    })
}

/// A technique built on a manifold split, seen in the input's terms: [`Technique::base_mesh`]
/// is the input, [`Technique::update_base`] takes the input's positions (copies follow their
/// sources); everything else is the inner technique's.
pub struct SplitInput {
    inner: Box<dyn Technique>,
    input: ControlMesh,
    split: ManifoldSplit,
}

impl Technique for SplitInput {
    fn id(&self) -> TechniqueId {
        self.inner.id()
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.inner.bbox()
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        self.inner.patch_arrays()
    }

    fn check(&self, params: &FrameParams) -> Result<()> {
        self.inner.check(params)
    }

    fn patch_pipeline(&self, patch: PatchType) -> PatchPipeline {
        self.inner.patch_pipeline(patch)
    }

    fn surface_build(&self, params: &FrameParams) -> bool {
        self.inner.surface_build(params)
    }

    fn set_layout_bindings(&self) -> &'static [BindingDesc] {
        self.inner.set_layout_bindings()
    }

    fn descriptor_set(&self, slot: usize) -> Option<&DescriptorSet> {
        self.inner.descriptor_set(slot)
    }

    fn max_vertices_per_patch(&self, params: &FrameParams, array: usize) -> u64 {
        self.inner.max_vertices_per_patch(params, array)
    }

    fn triangles(&self, params: &FrameParams, array: usize) -> Option<u64> {
        self.inner.triangles(params, array)
    }

    /// The input mesh, where the inner technique has a base (it moves).
    fn base_mesh(&self) -> Option<&ControlMesh> {
        self.inner.base_mesh().map(|_| &self.input)
    }

    fn prepare_frame(&mut self, ctx: &mut crate::Context, params: &FrameParams) -> Result<()> {
        self.inner.prepare_frame(ctx, params)
    }

    /// The input's positions, each copy of a vertex given its source's.
    fn update_base(&mut self, slot: usize, positions: &[[f32; 3]]) -> Result<()> {
        if positions.len() != self.split.input_vertices() {
            return Err(TessError::BasePositionCount {
                given: positions.len(),
                expected: self.split.input_vertices(),
            });
        }
        self.inner.update_base(slot, &self.split.expand(positions))
    }

    fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        frame_set: &'a DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        self.inner.record_pre_pass(enc, frame_set, slot)
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        slot: usize,
        params: &FrameParams,
        pass: Pass,
        per_draw: u32,
    ) -> Result<DrawCounts> {
        self.inner
            .record_array(enc, array, slot, params, pass, per_draw)
    }

    fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        self.inner.face_point(patch, domain)
    }

    fn texcoord(&self, patch: u32, domain: [f32; 2], reparam: bool) -> Option<[f64; 2]> {
        self.inner.texcoord(patch, domain, reparam)
    }

    fn report_notes(&self) -> Vec<String> {
        let mut notes = self.inner.report_notes();
        notes.push(self.split.report.summary());
        notes
    }

    fn device_memory(&self) -> Vec<DeviceAllocation> {
        self.inner.device_memory()
    }
}
