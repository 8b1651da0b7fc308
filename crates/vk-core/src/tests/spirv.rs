//! Minimal shaders for vk-core's GPU tests, as SPIR-V words (vk-core has no shader compiler).

/// Assembled (spirv-as --target-env vulkan1.1) from:
/// OpCapability Shader
/// OpMemoryModel Logical GLSL450
/// OpEntryPoint Vertex %main "main" %pos %out
/// OpDecorate %pos Location 0
/// OpDecorate %out BuiltIn Position
/// %void = OpTypeVoid
/// %fn = OpTypeFunction %void
/// %float = OpTypeFloat 32
/// %v3 = OpTypeVector %float 3
/// %v4 = OpTypeVector %float 4
/// %pv3 = OpTypePointer Input %v3
/// %pv4 = OpTypePointer Output %v4
/// %pos = OpVariable %pv3 Input
/// %out = OpVariable %pv4 Output
/// %one = OpConstant %float 1
/// %main = OpFunction %void None %fn
/// %l = OpLabel
/// %p = OpLoad %v3 %pos
/// %x = OpCompositeExtract %float %p 0
/// %y = OpCompositeExtract %float %p 1
/// %z = OpCompositeExtract %float %p 2
/// %v = OpCompositeConstruct %v4 %x %y %z %one
/// OpStore %out %v
/// OpReturn
/// OpFunctionEnd
pub const VERT: &[u32] = &[
    0x07230203, 0x00010300, 0x00070000, 0x00000012, 0x00000000, 0x00020011, 0x00000001, 0x0003000e,
    0x00000000, 0x00000001, 0x0007000f, 0x00000000, 0x00000001, 0x6e69616d, 0x00000000, 0x00000002,
    0x00000003, 0x00040047, 0x00000002, 0x0000001e, 0x00000000, 0x00040047, 0x00000003, 0x0000000b,
    0x00000000, 0x00020013, 0x00000004, 0x00030021, 0x00000005, 0x00000004, 0x00030016, 0x00000006,
    0x00000020, 0x00040017, 0x00000007, 0x00000006, 0x00000003, 0x00040017, 0x00000008, 0x00000006,
    0x00000004, 0x00040020, 0x00000009, 0x00000001, 0x00000007, 0x00040020, 0x0000000a, 0x00000003,
    0x00000008, 0x0004003b, 0x00000009, 0x00000002, 0x00000001, 0x0004003b, 0x0000000a, 0x00000003,
    0x00000003, 0x0004002b, 0x00000006, 0x0000000b, 0x3f800000, 0x00050036, 0x00000004, 0x00000001,
    0x00000000, 0x00000005, 0x000200f8, 0x0000000c, 0x0004003d, 0x00000007, 0x0000000d, 0x00000002,
    0x00050051, 0x00000006, 0x0000000e, 0x0000000d, 0x00000000, 0x00050051, 0x00000006, 0x0000000f,
    0x0000000d, 0x00000001, 0x00050051, 0x00000006, 0x00000010, 0x0000000d, 0x00000002, 0x00070050,
    0x00000008, 0x00000011, 0x0000000e, 0x0000000f, 0x00000010, 0x0000000b, 0x0003003e, 0x00000003,
    0x00000011, 0x000100fd, 0x00010038,
];

/// Assembled (spirv-as --target-env vulkan1.1) from:
/// OpCapability Shader
/// OpMemoryModel Logical GLSL450
/// OpEntryPoint Fragment %main "main" %col
/// OpExecutionMode %main OriginUpperLeft
/// OpDecorate %col Location 0
/// %void = OpTypeVoid
/// %fn = OpTypeFunction %void
/// %float = OpTypeFloat 32
/// %v4 = OpTypeVector %float 4
/// %pv4 = OpTypePointer Output %v4
/// %col = OpVariable %pv4 Output
/// %one = OpConstant %float 1
/// %zero = OpConstant %float 0
/// %c = OpConstantComposite %v4 %one %zero %zero %one
/// %main = OpFunction %void None %fn
/// %l = OpLabel
/// OpStore %col %c
/// OpReturn
/// OpFunctionEnd
pub const FRAG: &[u32] = &[
    0x07230203, 0x00010300, 0x00070000, 0x0000000c, 0x00000000, 0x00020011, 0x00000001, 0x0003000e,
    0x00000000, 0x00000001, 0x0006000f, 0x00000004, 0x00000001, 0x6e69616d, 0x00000000, 0x00000002,
    0x00030010, 0x00000001, 0x00000007, 0x00040047, 0x00000002, 0x0000001e, 0x00000000, 0x00020013,
    0x00000003, 0x00030021, 0x00000004, 0x00000003, 0x00030016, 0x00000005, 0x00000020, 0x00040017,
    0x00000006, 0x00000005, 0x00000004, 0x00040020, 0x00000007, 0x00000003, 0x00000006, 0x0004003b,
    0x00000007, 0x00000002, 0x00000003, 0x0004002b, 0x00000005, 0x00000008, 0x3f800000, 0x0004002b,
    0x00000005, 0x00000009, 0x00000000, 0x0007002c, 0x00000006, 0x0000000a, 0x00000008, 0x00000009,
    0x00000009, 0x00000008, 0x00050036, 0x00000003, 0x00000001, 0x00000000, 0x00000004, 0x000200f8,
    0x0000000b, 0x0003003e, 0x00000002, 0x0000000a, 0x000100fd, 0x00010038,
];

/// Assembled (spirv-as --target-env vulkan1.1) from:
/// OpCapability Shader
/// OpMemoryModel Logical GLSL450
/// OpEntryPoint GLCompute %main "main"
/// OpExecutionMode %main LocalSize 1 1 1
/// OpDecorate %arr ArrayStride 4
/// OpMemberDecorate %S 0 Offset 0
/// OpDecorate %S Block
/// OpDecorate %buf DescriptorSet 0
/// OpDecorate %buf Binding 0
/// %void = OpTypeVoid
/// %fn = OpTypeFunction %void
/// %uint = OpTypeInt 32 0
/// %arr = OpTypeRuntimeArray %uint
/// %S = OpTypeStruct %arr
/// %pS = OpTypePointer StorageBuffer %S
/// %buf = OpVariable %pS StorageBuffer
/// %pu = OpTypePointer StorageBuffer %uint
/// %c0 = OpConstant %uint 0
/// %c7 = OpConstant %uint 7
/// %main = OpFunction %void None %fn
/// %l = OpLabel
/// %ptr = OpAccessChain %pu %buf %c0 %c0
/// OpStore %ptr %c7
/// OpReturn
/// OpFunctionEnd
pub const COMP: &[u32] = &[
    0x07230203, 0x00010300, 0x00070000, 0x0000000e, 0x00000000, 0x00020011, 0x00000001, 0x0003000e,
    0x00000000, 0x00000001, 0x0005000f, 0x00000005, 0x00000001, 0x6e69616d, 0x00000000, 0x00060010,
    0x00000001, 0x00000011, 0x00000001, 0x00000001, 0x00000001, 0x00040047, 0x00000002, 0x00000006,
    0x00000004, 0x00050048, 0x00000003, 0x00000000, 0x00000023, 0x00000000, 0x00030047, 0x00000003,
    0x00000002, 0x00040047, 0x00000004, 0x00000022, 0x00000000, 0x00040047, 0x00000004, 0x00000021,
    0x00000000, 0x00020013, 0x00000005, 0x00030021, 0x00000006, 0x00000005, 0x00040015, 0x00000007,
    0x00000020, 0x00000000, 0x0003001d, 0x00000002, 0x00000007, 0x0003001e, 0x00000003, 0x00000002,
    0x00040020, 0x00000008, 0x0000000c, 0x00000003, 0x0004003b, 0x00000008, 0x00000004, 0x0000000c,
    0x00040020, 0x00000009, 0x0000000c, 0x00000007, 0x0004002b, 0x00000007, 0x0000000a, 0x00000000,
    0x0004002b, 0x00000007, 0x0000000b, 0x00000007, 0x00050036, 0x00000005, 0x00000001, 0x00000000,
    0x00000006, 0x000200f8, 0x0000000c, 0x00060041, 0x00000009, 0x0000000d, 0x00000004, 0x0000000a,
    0x0000000a, 0x0003003e, 0x0000000d, 0x0000000b, 0x000100fd, 0x00010038,
];

/// Assembled (spirv-as --target-env vulkan1.1) from:
/// OpCapability Shader
/// OpCapability TransformFeedback
/// OpMemoryModel Logical GLSL450
/// OpEntryPoint Vertex %main "main" %pos %out %cap
/// OpExecutionMode %main Xfb
/// OpDecorate %pos Location 0
/// OpDecorate %out BuiltIn Position
/// OpDecorate %cap Location 0
/// OpDecorate %cap XfbBuffer 0
/// OpDecorate %cap XfbStride 16
/// OpDecorate %cap Offset 0
/// %void = OpTypeVoid
/// %fn = OpTypeFunction %void
/// %float = OpTypeFloat 32
/// %v3 = OpTypeVector %float 3
/// %v4 = OpTypeVector %float 4
/// %pv3 = OpTypePointer Input %v3
/// %pv4 = OpTypePointer Output %v4
/// %pos = OpVariable %pv3 Input
/// %out = OpVariable %pv4 Output
/// %cap = OpVariable %pv4 Output
/// %one = OpConstant %float 1
/// %main = OpFunction %void None %fn
/// %l = OpLabel
/// %p = OpLoad %v3 %pos
/// %x = OpCompositeExtract %float %p 0
/// %y = OpCompositeExtract %float %p 1
/// %z = OpCompositeExtract %float %p 2
/// %v = OpCompositeConstruct %v4 %x %y %z %one
/// OpStore %out %v
/// OpStore %cap %v
/// OpReturn
/// OpFunctionEnd
pub const XFB_VERT: &[u32] = &[
    0x07230203, 0x00010300, 0x00070000, 0x00000013, 0x00000000, 0x00020011, 0x00000001, 0x00020011,
    0x00000035, 0x0003000e, 0x00000000, 0x00000001, 0x0008000f, 0x00000000, 0x00000001, 0x6e69616d,
    0x00000000, 0x00000002, 0x00000003, 0x00000004, 0x00030010, 0x00000001, 0x0000000b, 0x00040047,
    0x00000002, 0x0000001e, 0x00000000, 0x00040047, 0x00000003, 0x0000000b, 0x00000000, 0x00040047,
    0x00000004, 0x0000001e, 0x00000000, 0x00040047, 0x00000004, 0x00000024, 0x00000000, 0x00040047,
    0x00000004, 0x00000025, 0x00000010, 0x00040047, 0x00000004, 0x00000023, 0x00000000, 0x00020013,
    0x00000005, 0x00030021, 0x00000006, 0x00000005, 0x00030016, 0x00000007, 0x00000020, 0x00040017,
    0x00000008, 0x00000007, 0x00000003, 0x00040017, 0x00000009, 0x00000007, 0x00000004, 0x00040020,
    0x0000000a, 0x00000001, 0x00000008, 0x00040020, 0x0000000b, 0x00000003, 0x00000009, 0x0004003b,
    0x0000000a, 0x00000002, 0x00000001, 0x0004003b, 0x0000000b, 0x00000003, 0x00000003, 0x0004003b,
    0x0000000b, 0x00000004, 0x00000003, 0x0004002b, 0x00000007, 0x0000000c, 0x3f800000, 0x00050036,
    0x00000005, 0x00000001, 0x00000000, 0x00000006, 0x000200f8, 0x0000000d, 0x0004003d, 0x00000008,
    0x0000000e, 0x00000002, 0x00050051, 0x00000007, 0x0000000f, 0x0000000e, 0x00000000, 0x00050051,
    0x00000007, 0x00000010, 0x0000000e, 0x00000001, 0x00050051, 0x00000007, 0x00000011, 0x0000000e,
    0x00000002, 0x00070050, 0x00000009, 0x00000012, 0x0000000f, 0x00000010, 0x00000011, 0x0000000c,
    0x0003003e, 0x00000003, 0x00000012, 0x0003003e, 0x00000004, 0x00000012, 0x000100fd, 0x00010038,
];

/// Samples the texture at set 0 binding 1 at texel (0, 0)'s centre of a 5×3 texture, at LOD 0
/// into vec4 0 and at LOD 8 (clamped to the last level) into vec4 1 of the storage buffer at
/// binding 0. Assembled (spirv-as --target-env vulkan1.1) from:
/// OpCapability Shader
/// OpMemoryModel Logical GLSL450
/// OpEntryPoint GLCompute %main "main"
/// OpExecutionMode %main LocalSize 1 1 1
/// OpDecorate %arr ArrayStride 16
/// OpMemberDecorate %S 0 Offset 0
/// OpDecorate %S Block
/// OpDecorate %buf DescriptorSet 0
/// OpDecorate %buf Binding 0
/// OpDecorate %tex DescriptorSet 0
/// OpDecorate %tex Binding 1
/// %void = OpTypeVoid
/// %fn = OpTypeFunction %void
/// %uint = OpTypeInt 32 0
/// %float = OpTypeFloat 32
/// %v2 = OpTypeVector %float 2
/// %v4 = OpTypeVector %float 4
/// %arr = OpTypeRuntimeArray %v4
/// %S = OpTypeStruct %arr
/// %pS = OpTypePointer StorageBuffer %S
/// %buf = OpVariable %pS StorageBuffer
/// %pv4 = OpTypePointer StorageBuffer %v4
/// %img = OpTypeImage %float 2D 0 0 0 1 Unknown
/// %simg = OpTypeSampledImage %img
/// %psimg = OpTypePointer UniformConstant %simg
/// %tex = OpVariable %psimg UniformConstant
/// %c0 = OpConstant %uint 0
/// %c1 = OpConstant %uint 1
/// %lod0 = OpConstant %float 0
/// %lod8 = OpConstant %float 8
/// %u = OpConstant %float 0.1
/// %v = OpConstant %float 0.16666667
/// %uv = OpConstantComposite %v2 %u %v
/// %main = OpFunction %void None %fn
/// %l = OpLabel
/// %s = OpLoad %simg %tex
/// %a = OpImageSampleExplicitLod %v4 %s %uv Lod %lod0
/// %p0 = OpAccessChain %pv4 %buf %c0 %c0
/// OpStore %p0 %a
/// %b = OpImageSampleExplicitLod %v4 %s %uv Lod %lod8
/// %p1 = OpAccessChain %pv4 %buf %c0 %c1
/// OpStore %p1 %b
/// OpReturn
/// OpFunctionEnd
pub const SAMPLE_COMP: &[u32] = &[
    0x07230203, 0x00010300, 0x00070000, 0x0000001e, 0x00000000, 0x00020011, 0x00000001, 0x0003000e,
    0x00000000, 0x00000001, 0x0005000f, 0x00000005, 0x00000001, 0x6e69616d, 0x00000000, 0x00060010,
    0x00000001, 0x00000011, 0x00000001, 0x00000001, 0x00000001, 0x00040047, 0x00000002, 0x00000006,
    0x00000010, 0x00050048, 0x00000003, 0x00000000, 0x00000023, 0x00000000, 0x00030047, 0x00000003,
    0x00000002, 0x00040047, 0x00000004, 0x00000022, 0x00000000, 0x00040047, 0x00000004, 0x00000021,
    0x00000000, 0x00040047, 0x00000005, 0x00000022, 0x00000000, 0x00040047, 0x00000005, 0x00000021,
    0x00000001, 0x00020013, 0x00000006, 0x00030021, 0x00000007, 0x00000006, 0x00040015, 0x00000008,
    0x00000020, 0x00000000, 0x00030016, 0x00000009, 0x00000020, 0x00040017, 0x0000000a, 0x00000009,
    0x00000002, 0x00040017, 0x0000000b, 0x00000009, 0x00000004, 0x0003001d, 0x00000002, 0x0000000b,
    0x0003001e, 0x00000003, 0x00000002, 0x00040020, 0x0000000c, 0x0000000c, 0x00000003, 0x0004003b,
    0x0000000c, 0x00000004, 0x0000000c, 0x00040020, 0x0000000d, 0x0000000c, 0x0000000b, 0x00090019,
    0x0000000e, 0x00000009, 0x00000001, 0x00000000, 0x00000000, 0x00000000, 0x00000001, 0x00000000,
    0x0003001b, 0x0000000f, 0x0000000e, 0x00040020, 0x00000010, 0x00000000, 0x0000000f, 0x0004003b,
    0x00000010, 0x00000005, 0x00000000, 0x0004002b, 0x00000008, 0x00000011, 0x00000000, 0x0004002b,
    0x00000008, 0x00000012, 0x00000001, 0x0004002b, 0x00000009, 0x00000013, 0x00000000, 0x0004002b,
    0x00000009, 0x00000014, 0x41000000, 0x0004002b, 0x00000009, 0x00000015, 0x3dcccccd, 0x0004002b,
    0x00000009, 0x00000016, 0x3e2aaaab, 0x0005002c, 0x0000000a, 0x00000017, 0x00000015, 0x00000016,
    0x00050036, 0x00000006, 0x00000001, 0x00000000, 0x00000007, 0x000200f8, 0x00000018, 0x0004003d,
    0x0000000f, 0x00000019, 0x00000005, 0x00070058, 0x0000000b, 0x0000001a, 0x00000019, 0x00000017,
    0x00000002, 0x00000013, 0x00060041, 0x0000000d, 0x0000001b, 0x00000004, 0x00000011, 0x00000011,
    0x0003003e, 0x0000001b, 0x0000001a, 0x00070058, 0x0000000b, 0x0000001c, 0x00000019, 0x00000017,
    0x00000002, 0x00000014, 0x00060041, 0x0000000d, 0x0000001d, 0x00000004, 0x00000011, 0x00000012,
    0x0003003e, 0x0000001d, 0x0000001c, 0x000100fd, 0x00010038,
];
