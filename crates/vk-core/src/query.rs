//! GPU timestamps, pipeline statistics (TCS patches, TES invocations, clipping primitives) and
//! transform-feedback stream counts (primitives written / needed, to size and check captures).
use crate::device::{Device, DeviceShared};
use crate::error::{Result, VkContext, VkError};
use crate::retire::Retired;
use ash::vk;
use std::sync::Arc;

/// Counters read back from a pipeline-statistics query, in the order Vulkan writes them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PipelineStatistics {
    pub input_assembly_vertices: u64,
    pub vertex_shader_invocations: u64,
    pub clipping_invocations: u64,
    pub clipping_primitives: u64,
    pub fragment_shader_invocations: u64,
    pub tess_control_patches: u64,
    pub tess_evaluation_invocations: u64,
}

impl PipelineStatistics {
    /// The flags in bit order (Vulkan writes results in ascending bit order).
    pub fn flags() -> vk::QueryPipelineStatisticFlags {
        vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_VERTICES
            | vk::QueryPipelineStatisticFlags::VERTEX_SHADER_INVOCATIONS
            | vk::QueryPipelineStatisticFlags::CLIPPING_INVOCATIONS
            | vk::QueryPipelineStatisticFlags::CLIPPING_PRIMITIVES
            | vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS
            | vk::QueryPipelineStatisticFlags::TESSELLATION_CONTROL_SHADER_PATCHES
            | vk::QueryPipelineStatisticFlags::TESSELLATION_EVALUATION_SHADER_INVOCATIONS
    }
}

/// Counters of a transform-feedback stream query: what was written to the bound buffers, and what
/// would have been written had they been large enough (needed > written means overflow).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TransformFeedbackCounts {
    pub primitives_written: u64,
    pub primitives_needed: u64,
}

/// A pool of `count` timestamp, pipeline-statistics or transform-feedback stream queries.
pub struct QueryPool {
    pub(crate) raw: vk::QueryPool,
    pub ty: vk::QueryType,
    pub count: u32,
    pub(crate) name: String,
    device: Arc<DeviceShared>,
}

impl QueryPool {
    pub fn timestamps(device: &Device, name: &str, count: u32) -> Result<Self> {
        if !device.info.caps.timestamps {
            return Err(VkError::Unsupported {
                device: device.info.name.clone(),
                what: "timestamp queries on its queue",
            });
        }
        Self::new(
            device,
            name,
            vk::QueryType::TIMESTAMP,
            count,
            vk::QueryPipelineStatisticFlags::empty(),
        )
    }

    pub fn statistics(device: &Device, name: &str, count: u32) -> Result<Self> {
        if !device.info.caps.pipeline_statistics_query {
            return Err(VkError::Unsupported {
                device: device.info.name.clone(),
                what: "pipeline-statistics queries (pipelineStatisticsQuery)",
            });
        }
        Self::new(
            device,
            name,
            vk::QueryType::PIPELINE_STATISTICS,
            count,
            PipelineStatistics::flags(),
        )
    }

    /// Transform-feedback stream queries (VK_EXT_transform_feedback, `transformFeedbackQueries`);
    /// a typed error on a device without them.
    pub fn transform_feedback_stream(device: &Device, name: &str, count: u32) -> Result<Self> {
        device.transform_feedback()?;
        if !device.info.caps.transform_feedback_queries {
            return Err(VkError::Unsupported {
                device: device.info.name.clone(),
                what: "transform-feedback queries (transformFeedbackQueries)",
            });
        }
        Self::new(
            device,
            name,
            vk::QueryType::TRANSFORM_FEEDBACK_STREAM_EXT,
            count,
            vk::QueryPipelineStatisticFlags::empty(),
        )
    }

    fn new(
        device: &Device,
        name: &str,
        ty: vk::QueryType,
        count: u32,
        stats: vk::QueryPipelineStatisticFlags,
    ) -> Result<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(ty)
            .query_count(count)
            .pipeline_statistics(stats);
        // SAFETY: device live; the feature was checked above.
        let raw = unsafe { device.raw.create_query_pool(&info, None) }.ctx("vkCreateQueryPool")?;
        device.created(1);
        device.set_name(raw, name);
        Ok(Self {
            raw,
            ty,
            count,
            name: name.to_owned(),
            device: device.shared.clone(),
        })
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub(crate) fn check_index(&self, call: &'static str, query: u32) -> Result<()> {
        if query < self.count {
            Ok(())
        } else {
            Err(VkError::QueryIndex {
                call,
                pool: self.name.clone(),
                index: query,
                count: self.count,
            })
        }
    }

    fn check_type(&self, call: &'static str, expected: vk::QueryType) -> Result<()> {
        if self.ty == expected {
            Ok(())
        } else {
            Err(VkError::QueryType {
                call,
                pool: self.name.clone(),
                expected,
                found: self.ty,
            })
        }
    }

    /// Waits for and reads `N` 64-bit values per query (ash takes one `T` per query: its size
    /// is the stride, so a flat `u64` slice would claim 7× too many statistics queries).
    fn results<const N: usize>(&self) -> Result<Vec<[u64; N]>> {
        let mut data = vec![[0u64; N]; self.count as usize];
        // SAFETY: one [u64; N] per query, N matching the query type's value count.
        unsafe {
            self.device.raw.get_query_pool_results(
                self.raw,
                0,
                &mut data,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .ctx("vkGetQueryPoolResults")?;
        Ok(data)
    }

    pub fn statistics_results(&self) -> Result<Vec<PipelineStatistics>> {
        self.check_type("vkGetQueryPoolResults", vk::QueryType::PIPELINE_STATISTICS)?;
        Ok(self
            .results::<7>()?
            .into_iter()
            .map(|c| PipelineStatistics {
                input_assembly_vertices: c[0],
                vertex_shader_invocations: c[1],
                clipping_invocations: c[2],
                clipping_primitives: c[3],
                fragment_shader_invocations: c[4],
                tess_control_patches: c[5],
                tess_evaluation_invocations: c[6],
            })
            .collect())
    }

    /// Waits for and reads every query's (primitives written, primitives needed).
    pub fn transform_feedback_results(&self) -> Result<Vec<TransformFeedbackCounts>> {
        self.check_type(
            "vkGetQueryPoolResults",
            vk::QueryType::TRANSFORM_FEEDBACK_STREAM_EXT,
        )?;
        Ok(self
            .results::<2>()?
            .into_iter()
            .map(|c| TransformFeedbackCounts {
                primitives_written: c[0],
                primitives_needed: c[1],
            })
            .collect())
    }

    /// Timestamp differences in nanoseconds between consecutive pairs (0–1, 2–3, …).
    pub fn durations_ns(&self) -> Result<Vec<f64>> {
        let period = self.device.info.caps.timestamp_period_ns as f64;
        self.check_type("vkGetQueryPoolResults", vk::QueryType::TIMESTAMP)?;
        let raw = self.results::<1>()?;
        Ok(raw
            .chunks_exact(2)
            .map(|p| p[1][0].wrapping_sub(p[0][0]) as f64 * period)
            .collect())
    }
}

impl Drop for QueryPool {
    fn drop(&mut self) {
        self.device.retire(Retired::QueryPool(self.raw));
    }
}
