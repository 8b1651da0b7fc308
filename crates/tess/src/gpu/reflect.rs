//! A small SPIR-V reader: what glslang actually laid out (names, member offsets, descriptor
//! bindings, array strides, transform-feedback decorations, input locations), so tests can hold
//! the Rust mirrors in [`crate::gpu`] and [`crate::techniques::bft::layout`] against the compiled shaders.
//!
//! It reads the module's debug names (the build keeps them), so it finds blocks and structs by
//! their GLSL type names. Not a validator: it reads only the instructions it needs.
use std::collections::HashMap;

const OP_NAME: u32 = 5;
const OP_TYPE_INT: u32 = 21;
const OP_TYPE_FLOAT: u32 = 22;
const OP_TYPE_VECTOR: u32 = 23;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_STRUCT: u32 = 30;
const OP_TYPE_POINTER: u32 = 32;
const OP_CONSTANT: u32 = 43;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const OP_MEMBER_DECORATE: u32 = 72;

const DECORATION_ARRAY_STRIDE: u32 = 6;
const DECORATION_LOCATION: u32 = 30;
const DECORATION_BINDING: u32 = 33;
const DECORATION_DESCRIPTOR_SET: u32 = 34;
const DECORATION_OFFSET: u32 = 35;
const DECORATION_XFB_BUFFER: u32 = 36;
const DECORATION_XFB_STRIDE: u32 = 37;

const STORAGE_INPUT: u32 = 1;
const STORAGE_OUTPUT: u32 = 3;

/// Why SPIR-V words could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReflectError {
    #[error("not a SPIR-V module (bad magic number or header)")]
    NotSpirv,
    #[error("truncated or malformed instruction at word {0}")]
    Malformed(usize),
}

/// A type the reader understands.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Type {
    Scalar { bytes: u32 },
    Vector { component: u32, count: u32 },
    Array { element: u32, length_id: u32 },
    RuntimeArray { element: u32 },
    Struct { members: Vec<u32> },
    Pointer { storage: u32, pointee: u32 },
}

/// One output variable written to a transform-feedback buffer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct XfbOutput {
    /// GLSL name of the output.
    pub name: String,
    pub buffer: u32,
    pub stride: u32,
    pub offset: u32,
}

/// A descriptor-bound block: its variable's set and binding, by the block's type name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockBinding {
    pub set: u32,
    pub binding: u32,
}

/// The parts of a SPIR-V module the layout tests read.
#[derive(Clone, Debug, Default)]
pub struct Reflection {
    names: HashMap<u32, String>,
    types: HashMap<u32, Type>,
    constants: HashMap<u32, u32>,
    /// (id, type, storage class) of every module-scope variable.
    variables: Vec<(u32, u32, u32)>,
    decorations: HashMap<u32, Vec<(u32, u32)>>,
    member_offsets: HashMap<u32, Vec<(u32, u32)>>,
}

impl Reflection {
    /// Reads the module.
    pub fn new(words: &[u32]) -> Result<Self, ReflectError> {
        if words.len() < 5 || words[0] != 0x0723_0203 {
            return Err(ReflectError::NotSpirv);
        }
        let mut r = Reflection::default();
        let mut i = 5;
        while i < words.len() {
            let count = (words[i] >> 16) as usize;
            let op = words[i] & 0xffff;
            if count == 0 || i + count > words.len() {
                return Err(ReflectError::Malformed(i));
            }
            let ins = &words[i..i + count];
            let arg = |k: usize| ins.get(k).copied().ok_or(ReflectError::Malformed(i));
            match op {
                OP_NAME => {
                    r.names.insert(arg(1)?, string(&ins[2..]));
                }
                OP_TYPE_INT | OP_TYPE_FLOAT => {
                    r.types.insert(arg(1)?, Type::Scalar { bytes: arg(2)? / 8 });
                }
                OP_TYPE_VECTOR => {
                    r.types.insert(
                        arg(1)?,
                        Type::Vector {
                            component: arg(2)?,
                            count: arg(3)?,
                        },
                    );
                }
                OP_TYPE_ARRAY => {
                    r.types.insert(
                        arg(1)?,
                        Type::Array {
                            element: arg(2)?,
                            length_id: arg(3)?,
                        },
                    );
                }
                OP_TYPE_RUNTIME_ARRAY => {
                    r.types
                        .insert(arg(1)?, Type::RuntimeArray { element: arg(2)? });
                }
                OP_TYPE_STRUCT => {
                    r.types.insert(
                        arg(1)?,
                        Type::Struct {
                            members: ins[2..].to_vec(),
                        },
                    );
                }
                OP_TYPE_POINTER => {
                    r.types.insert(
                        arg(1)?,
                        Type::Pointer {
                            storage: arg(2)?,
                            pointee: arg(3)?,
                        },
                    );
                }
                OP_CONSTANT if count == 4 => {
                    r.constants.insert(arg(2)?, arg(3)?);
                }
                OP_VARIABLE => r.variables.push((arg(2)?, arg(1)?, arg(3)?)),
                OP_DECORATE if count >= 3 => {
                    let value = ins.get(3).copied().unwrap_or(0);
                    r.decorations
                        .entry(arg(1)?)
                        .or_default()
                        .push((arg(2)?, value));
                }
                OP_MEMBER_DECORATE if count >= 5 && ins[3] == DECORATION_OFFSET => {
                    r.member_offsets
                        .entry(arg(1)?)
                        .or_default()
                        .push((arg(2)?, arg(4)?));
                }
                _ => {}
            }
            i += count;
        }
        Ok(r)
    }

    fn decoration(&self, id: u32, decoration: u32) -> Option<u32> {
        self.decorations
            .get(&id)?
            .iter()
            .find(|(d, _)| *d == decoration)
            .map(|&(_, v)| v)
    }

    /// Ids of the laid-out structs (those with member offsets) named `name`. glslang emits a
    /// second, offset-free copy of a struct that a shader copies into a local variable.
    fn laid_out_structs(&self, name: &str) -> Vec<u32> {
        let mut ids: Vec<u32> = self
            .names
            .iter()
            .filter(|(id, n)| {
                n.as_str() == name
                    && matches!(self.types.get(id), Some(Type::Struct { .. }))
                    && self.member_offsets.contains_key(id)
            })
            .map(|(&id, _)| id)
            .collect();
        ids.sort_unstable();
        ids
    }

    /// Member offsets, in member order, of every laid-out struct or block named `name` (one
    /// entry per distinct layout glslang emitted; empty when there is none).
    pub fn member_offsets(&self, name: &str) -> Vec<Vec<u32>> {
        let mut layouts: Vec<Vec<u32>> = self
            .laid_out_structs(name)
            .into_iter()
            .map(|id| {
                let mut m = self.member_offsets[&id].clone();
                m.sort_unstable();
                m.into_iter().map(|(_, o)| o).collect()
            })
            .collect();
        layouts.dedup();
        layouts
    }

    /// Bytes of a type as laid out: scalars, vectors, arrays (by their stride), structs (last
    /// member's offset plus its size). `None` for a runtime array or an unknown type.
    fn type_size(&self, id: u32) -> Option<u32> {
        match self.types.get(&id)? {
            Type::Scalar { bytes } => Some(*bytes),
            Type::Vector { component, count } => Some(self.type_size(*component)? * count),
            Type::Array { length_id, .. } => Some(
                self.decoration(id, DECORATION_ARRAY_STRIDE)? * self.constants.get(length_id)?,
            ),
            Type::Struct { members } => {
                let last = members.len().checked_sub(1)? as u32;
                let offset = self
                    .member_offsets
                    .get(&id)?
                    .iter()
                    .find(|(m, _)| *m == last)?
                    .1;
                Some(offset + self.type_size(*members.last()?)?)
            }
            Type::RuntimeArray { .. } | Type::Pointer { .. } => None,
        }
    }

    /// Size in bytes of the laid-out struct or block `name` (see `type_size`); `None`
    /// when absent, ambiguous, or ending in a runtime array.
    pub fn struct_size(&self, name: &str) -> Option<u32> {
        let sizes: Vec<u32> = self
            .laid_out_structs(name)
            .into_iter()
            .filter_map(|id| self.type_size(id))
            .collect();
        match sizes.as_slice() {
            [s, rest @ ..] if rest.iter().all(|r| r == s) => Some(*s),
            _ => None,
        }
    }

    /// The block type (struct) behind a module-scope variable.
    fn variable_block(&self, var_type: u32) -> Option<u32> {
        match self.types.get(&var_type)? {
            Type::Pointer { pointee, .. } => Some(*pointee),
            _ => None,
        }
    }

    /// Set and binding of the variable whose block type is named `block`.
    pub fn binding(&self, block: &str) -> Option<BlockBinding> {
        let ids = self.laid_out_structs(block);
        self.variables.iter().find_map(|&(var, ty, _)| {
            let b = self.variable_block(ty)?;
            if !ids.contains(&b) {
                return None;
            }
            Some(BlockBinding {
                set: self.decoration(var, DECORATION_DESCRIPTOR_SET)?,
                binding: self.decoration(var, DECORATION_BINDING)?,
            })
        })
    }

    /// `ArrayStride` of the runtime array that ends block `block`.
    pub fn runtime_array_stride(&self, block: &str) -> Option<u32> {
        self.laid_out_structs(block).into_iter().find_map(|id| {
            let Some(Type::Struct { members }) = self.types.get(&id) else {
                return None;
            };
            let last = *members.last()?;
            match self.types.get(&last)? {
                Type::RuntimeArray { .. } => self.decoration(last, DECORATION_ARRAY_STRIDE),
                _ => None,
            }
        })
    }

    /// `ArrayStride` of the fixed-size array member `member` (0-based) of struct `name`.
    pub fn member_array_stride(&self, name: &str, member: u32) -> Option<u32> {
        self.laid_out_structs(name).into_iter().find_map(|id| {
            let Some(Type::Struct { members }) = self.types.get(&id) else {
                return None;
            };
            let ty = *members.get(member as usize)?;
            match self.types.get(&ty)? {
                Type::Array { .. } => self.decoration(ty, DECORATION_ARRAY_STRIDE),
                _ => None,
            }
        })
    }

    /// Every output variable with transform-feedback decorations, by offset.
    pub fn xfb_outputs(&self) -> Vec<XfbOutput> {
        let mut out: Vec<XfbOutput> = self
            .variables
            .iter()
            .filter(|&&(_, _, storage)| storage == STORAGE_OUTPUT)
            .filter_map(|&(var, _, _)| {
                Some(XfbOutput {
                    name: self.names.get(&var).cloned().unwrap_or_default(),
                    buffer: self.decoration(var, DECORATION_XFB_BUFFER)?,
                    stride: self.decoration(var, DECORATION_XFB_STRIDE)?,
                    offset: self.decoration(var, DECORATION_OFFSET)?,
                })
            })
            .collect();
        out.sort_by_key(|o| o.offset);
        out
    }

    /// Whether any id carries an `XfbBuffer` decoration.
    pub fn has_xfb(&self) -> bool {
        self.decorations
            .values()
            .flatten()
            .any(|&(d, _)| d == DECORATION_XFB_BUFFER)
    }

    /// Location and size in bytes of the input variable named `name`.
    pub fn input(&self, name: &str) -> Option<(u32, u32)> {
        self.interface(name, STORAGE_INPUT)
    }

    /// Location and size in bytes of the output variable named `name`.
    pub fn output(&self, name: &str) -> Option<(u32, u32)> {
        self.interface(name, STORAGE_OUTPUT)
    }

    fn interface(&self, name: &str, class: u32) -> Option<(u32, u32)> {
        self.variables.iter().find_map(|&(var, ty, storage)| {
            if storage != class || self.names.get(&var).map(String::as_str) != Some(name) {
                return None;
            }
            let location = self.decoration(var, DECORATION_LOCATION)?;
            Some((location, self.type_size(self.variable_block(ty)?)?))
        })
    }
}

/// A literal string operand (UTF-8, nul-terminated, packed little-endian).
pub(crate) fn string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .take_while(|&b| b != 0)
        .collect();
    String::from_utf8_lossy(&bytes).into_owned()
}
