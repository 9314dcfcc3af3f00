//! The interface of a compiled shader, reflected from its SPIR-V (read
//! with `rspirv`): descriptor bindings (number, name, kind, array size),
//! specialisation constants (id, name), the push-constant block's size and
//! the byte layout of every struct in its buffers and push constants.
//! Pipelines build their descriptor set layouts from it and check what the
//! host binds and specialises against it, so the `BINDING_*` and `SPEC_*`
//! numbers of `src/gpu/shader_interface.rs` are the only place both sides meet;
//! the GPU structs of `passes::gpu` are checked member by member against
//! the layouts here (`tests/scene/interface.rs`).

use std::collections::{BTreeMap, HashMap};

use rspirv::dr::{Instruction, Operand};
use rspirv::spirv::{Decoration, Op, StorageClass};

use ash::vk;

/// What a descriptor binding holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// A top-level acceleration structure.
    AccelerationStructure,
    /// A storage buffer.
    StorageBuffer,
    /// A storage image (GENERAL layout).
    StorageImage,
    /// An array of this many combined image samplers (SHADER_READ_ONLY_OPTIMAL).
    SampledImages(u32),
}

impl BindingKind {
    /// The Vulkan descriptor type.
    pub fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            Self::AccelerationStructure => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            Self::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            Self::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            Self::SampledImages(_) => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    }

    /// Descriptors at the binding (array elements).
    pub fn count(self) -> u32 {
        match self {
            Self::SampledImages(n) => n,
            _ => 1,
        }
    }
}

/// What does not match between a shader and the host.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InterfaceError {
    /// The SPIR-V could not be reflected.
    #[error("cannot reflect the shader's SPIR-V: {0}")]
    Reflect(String),
    /// A binding of a kind the renderer does not create.
    #[error("binding {binding} ({name}): {what} is not a descriptor kind the renderer creates")]
    Unsupported {
        /// The binding number.
        binding: u32,
        /// Its variable's name.
        name: String,
        /// The descriptor kind.
        what: String,
    },
    /// A binding outside descriptor set 0.
    #[error("binding {binding} ({name}) is in descriptor set {set}; the renderer uses set 0 only")]
    OtherSet {
        /// The binding number.
        binding: u32,
        /// Its variable's name.
        name: String,
        /// The set.
        set: u32,
    },
    /// The shader declares a binding the host gives nothing for.
    #[error("binding {binding} ({name}, {kind:?}) of the shader has no resource bound")]
    Missing {
        /// The binding number.
        binding: u32,
        /// Its variable's name.
        name: String,
        /// What the shader expects there.
        kind: BindingKind,
    },
    /// The host binds a resource of another kind than the shader's.
    #[error("binding {binding} ({name}): the shader declares {shader:?}, the host binds {host}")]
    Mismatch {
        /// The binding number.
        binding: u32,
        /// Its variable's name.
        name: String,
        /// What the shader declares.
        shader: BindingKind,
        /// What the host binds.
        host: String,
    },
    /// The host binds two resources at one binding.
    #[error("binding {0} is bound twice")]
    Twice(u32),
    /// The host specialises a constant id the shader does not have.
    #[error("specialisation constant id {id} is not in the shader (it has {known})")]
    UnknownSpecConstant {
        /// The id.
        id: u32,
        /// The ids and names the shader has.
        known: String,
    },
    /// The host pushes constants of another size than the shader's block.
    #[error("the host pushes {host} bytes of constants, the shader's push-constant block is {shader} bytes")]
    PushConstants {
        /// The host's size.
        host: u32,
        /// The shader's size.
        shader: u32,
    },
    /// A host struct's layout differs from the shader's.
    #[error("struct {glsl} (host {host}): {what}")]
    Layout {
        /// The GLSL struct name.
        glsl: String,
        /// The host type.
        host: String,
        /// The difference.
        what: String,
    },
}

/// One descriptor binding of a shader.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReflectedBinding {
    /// The GLSL variable (or block) name.
    pub name: String,
    /// What it holds.
    pub kind: BindingKind,
}

/// One member of a struct with an explicit layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Member {
    /// The GLSL member name.
    pub name: String,
    /// Byte offset from the start of the struct.
    pub offset: usize,
    /// Size in bytes.
    pub size: usize,
}

/// A struct with an explicit layout (in a buffer or push-constant block).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StructLayout {
    /// The GLSL struct name.
    pub name: String,
    /// Its members in declaration order.
    pub members: Vec<Member>,
    /// The array stride where the struct is the element of an array in a
    /// buffer (its size there), else `None`.
    pub stride: Option<usize>,
}

impl StructLayout {
    /// The struct's size: its array stride, else the end of its last member.
    pub fn size(&self) -> usize {
        self.stride.unwrap_or_else(|| self.members.last().map_or(0, |m| m.offset + m.size))
    }
}

/// A compute shader's interface.
#[derive(Debug, Clone, Default)]
pub struct ShaderInterface {
    /// Descriptor bindings of set 0, by binding number.
    pub bindings: BTreeMap<u32, ReflectedBinding>,
    /// Specialisation constants: id to name.
    pub spec_constants: BTreeMap<u32, String>,
    /// Size of the push-constant block in bytes (0 without one).
    pub push_constant_size: u32,
    /// Every struct with an explicit layout, by GLSL name.
    pub structs: BTreeMap<String, StructLayout>,
}

impl ShaderInterface {
    /// Reflects every resource `spirv` declares (used or not).
    pub fn reflect(spirv: &[u32]) -> Result<Self, InterfaceError> {
        let words = without_source_text(spirv)?;
        let module = rspirv::dr::load_words(words).map_err(|e| InterfaceError::Reflect(e.to_string()))?;
        let module = Module::new(&module);
        let mut this = Self::default();
        for inst in &module.variables {
            let id = inst.result_id.unwrap_or(0);
            let (Some(Operand::StorageClass(class)), Some(pointer)) = (inst.operands.first(), inst.result_type) else {
                continue;
            };
            let Some(&Ty::Pointer(pointee)) = module.types.get(&pointer) else { continue };
            match class {
                StorageClass::PushConstant => {
                    this.push_constant_size = module.size(pointee) as u32;
                    module.collect_structs(pointee, None, &mut this.structs);
                }
                StorageClass::StorageBuffer | StorageClass::UniformConstant | StorageClass::Uniform => {
                    let Some(&binding) = module.binding.get(&id) else { continue };
                    let set = module.set.get(&id).copied().unwrap_or(0);
                    // An anonymous block is named by its type.
                    let name = module
                        .names
                        .get(&id)
                        .filter(|n| !n.is_empty())
                        .or_else(|| module.names.get(&pointee))
                        .cloned()
                        .unwrap_or_default();
                    if set != 0 {
                        return Err(InterfaceError::OtherSet { binding, name, set });
                    }
                    let kind = match (class, module.types.get(&pointee)) {
                        (StorageClass::StorageBuffer, Some(Ty::Struct(_))) => BindingKind::StorageBuffer,
                        (_, Some(Ty::AccelerationStructure)) => BindingKind::AccelerationStructure,
                        (_, Some(Ty::StorageImage)) => BindingKind::StorageImage,
                        (_, Some(Ty::SampledImage)) => BindingKind::SampledImages(1),
                        (_, Some(&Ty::Array(element, length)))
                            if matches!(module.types.get(&element), Some(Ty::SampledImage)) =>
                        {
                            BindingKind::SampledImages(module.constants.get(&length).copied().unwrap_or(0))
                        }
                        (_, other) => {
                            return Err(InterfaceError::Unsupported {
                                binding,
                                name,
                                what: format!("{class:?} {other:?}"),
                            })
                        }
                    };
                    module.collect_structs(pointee, None, &mut this.structs);
                    this.bindings.insert(binding, ReflectedBinding { name, kind });
                }
                _ => {}
            }
        }
        for (&id, &spec_id) in &module.spec_id {
            this.spec_constants.insert(spec_id, module.names.get(&id).cloned().unwrap_or_default());
        }
        Ok(this)
    }

    /// The interface of a pipeline of several stages: the union of their
    /// bindings (a binding number two stages declare must hold the same
    /// kind), spec constants, structs, and the largest push-constant block.
    pub fn merge(mut self, other: ShaderInterface) -> Result<Self, InterfaceError> {
        for (binding, b) in other.bindings {
            match self.bindings.get(&binding) {
                Some(mine) if mine.kind != b.kind => {
                    return Err(InterfaceError::Mismatch {
                        binding,
                        name: mine.name.clone(),
                        shader: mine.kind,
                        host: format!("{:?} in another stage ({})", b.kind, b.name),
                    })
                }
                Some(_) => {}
                None => {
                    self.bindings.insert(binding, b);
                }
            }
        }
        self.spec_constants.extend(other.spec_constants);
        self.structs.extend(other.structs);
        self.push_constant_size = self.push_constant_size.max(other.push_constant_size);
        Ok(self)
    }

    /// Checks the host's specialisation constant ids against the shader's.
    pub fn check_spec_constants(&self, ids: impl IntoIterator<Item = u32>) -> Result<(), InterfaceError> {
        for id in ids {
            if !self.spec_constants.contains_key(&id) {
                let known: Vec<String> = self.spec_constants.iter().map(|(i, n)| format!("{i} {n}")).collect();
                return Err(InterfaceError::UnknownSpecConstant { id, known: known.join(", ") });
            }
        }
        Ok(())
    }

    /// Checks resources of the given kinds at the given binding numbers
    /// against the shader: every binding of the shader must get one
    /// resource of its kind. Resources at numbers the shader does not
    /// declare are allowed (passes share one set of scene bindings) and
    /// returned, so that the caller can leave them out.
    pub fn check_bindings(&self, host: &[(u32, BindingKind)]) -> Result<Vec<u32>, InterfaceError> {
        let mut seen = std::collections::BTreeSet::new();
        let mut unused = Vec::new();
        for &(binding, kind) in host {
            if !seen.insert(binding) {
                return Err(InterfaceError::Twice(binding));
            }
            match self.bindings.get(&binding) {
                None => unused.push(binding),
                Some(b) if b.kind == kind => {}
                Some(b) => {
                    return Err(InterfaceError::Mismatch {
                        binding,
                        name: b.name.clone(),
                        shader: b.kind,
                        host: format!("{kind:?}"),
                    })
                }
            }
        }
        if let Some((&binding, b)) = self.bindings.iter().find(|(n, _)| !seen.contains(n)) {
            return Err(InterfaceError::Missing { binding, name: b.name.clone(), kind: b.kind });
        }
        Ok(unused)
    }
}

/// `spirv` without the debug instructions that carry source text and
/// lines (OpSourceContinued, OpSource, OpSourceExtension, OpString, OpLine,
/// OpNoLine): reflection needs none of them, and glslang splits the
/// embedded source into OpSourceContinued strings at byte counts, inside
/// UTF-8 sequences, which `rspirv` refuses to decode.
fn without_source_text(spirv: &[u32]) -> Result<Vec<u32>, InterfaceError> {
    const DROPPED: [u32; 6] = [2, 3, 4, 7, 8, 317];
    let truncated = || InterfaceError::Reflect("truncated SPIR-V".into());
    let mut out = spirv.get(..5).ok_or_else(truncated)?.to_vec();
    let mut i = 5;
    while i < spirv.len() {
        let count = (spirv[i] >> 16) as usize;
        let instruction = spirv.get(i..i + count.max(1)).ok_or_else(truncated)?;
        if count == 0 {
            return Err(InterfaceError::Reflect(format!("an instruction of 0 words at word {i}")));
        }
        if !DROPPED.contains(&(spirv[i] & 0xffff)) {
            out.extend_from_slice(instruction);
        }
        i += count;
    }
    Ok(out)
}

/// A type of the module, as far as layouts and descriptors need it.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Ty {
    /// A scalar of this many bytes.
    Scalar(usize),
    /// Components of a type.
    Vector(u32, u32),
    /// Element type and the id of the length constant.
    Array(u32, u32),
    /// Element type.
    RuntimeArray(u32),
    /// Member types.
    Struct(Vec<u32>),
    /// Pointee type.
    Pointer(u32),
    StorageImage,
    SampledImage,
    AccelerationStructure,
    Other,
}

/// The parts of a SPIR-V module that reflection reads, indexed by id.
struct Module<'a> {
    names: HashMap<u32, String>,
    member_names: HashMap<(u32, u32), String>,
    binding: HashMap<u32, u32>,
    set: HashMap<u32, u32>,
    spec_id: HashMap<u32, u32>,
    stride: HashMap<u32, u32>,
    offset: HashMap<(u32, u32), usize>,
    types: HashMap<u32, Ty>,
    constants: HashMap<u32, u32>,
    variables: Vec<&'a Instruction>,
}

fn word(op: Option<&Operand>) -> Option<u32> {
    match op? {
        Operand::IdRef(w) | Operand::LiteralBit32(w) => Some(*w),
        _ => None,
    }
}

impl<'a> Module<'a> {
    fn new(m: &'a rspirv::dr::Module) -> Self {
        let mut this = Self {
            names: HashMap::new(),
            member_names: HashMap::new(),
            binding: HashMap::new(),
            set: HashMap::new(),
            spec_id: HashMap::new(),
            stride: HashMap::new(),
            offset: HashMap::new(),
            types: HashMap::new(),
            constants: HashMap::new(),
            variables: Vec::new(),
        };
        for i in &m.debug_names {
            let o = &i.operands;
            match (i.class.opcode, o.as_slice()) {
                (Op::Name, [Operand::IdRef(id), Operand::LiteralString(n)]) => {
                    this.names.insert(*id, n.clone());
                }
                (Op::MemberName, [Operand::IdRef(id), Operand::LiteralBit32(k), Operand::LiteralString(n)]) => {
                    this.member_names.insert((*id, *k), n.clone());
                }
                _ => {}
            }
        }
        for i in &m.annotations {
            let o = &i.operands;
            match (i.class.opcode, o.as_slice()) {
                (Op::Decorate, [Operand::IdRef(id), Operand::Decoration(d), rest @ ..]) => {
                    let value = word(rest.first()).unwrap_or(0);
                    let map = match d {
                        Decoration::Binding => &mut this.binding,
                        Decoration::DescriptorSet => &mut this.set,
                        Decoration::SpecId => &mut this.spec_id,
                        Decoration::ArrayStride => &mut this.stride,
                        _ => continue,
                    };
                    map.insert(*id, value);
                }
                (
                    Op::MemberDecorate,
                    [Operand::IdRef(id), Operand::LiteralBit32(k), Operand::Decoration(Decoration::Offset), rest @ ..],
                ) => {
                    this.offset.insert((*id, *k), word(rest.first()).unwrap_or(0) as usize);
                }
                _ => {}
            }
        }
        for i in &m.types_global_values {
            let Some(id) = i.result_id else { continue };
            let o = &i.operands;
            let w = |k: usize| word(o.get(k)).unwrap_or(0);
            let ty = match i.class.opcode {
                Op::TypeBool => Ty::Scalar(4),
                Op::TypeInt | Op::TypeFloat => Ty::Scalar(w(0) as usize / 8),
                Op::TypeVector | Op::TypeMatrix => Ty::Vector(w(0), w(1)),
                Op::TypeArray => Ty::Array(w(0), w(1)),
                Op::TypeRuntimeArray => Ty::RuntimeArray(w(0)),
                Op::TypeStruct => Ty::Struct((0..o.len()).map(w).collect()),
                Op::TypePointer => Ty::Pointer(w(1)),
                // Sampled = 2: a storage image.
                Op::TypeImage if w(5) == 2 => Ty::StorageImage,
                Op::TypeSampledImage => Ty::SampledImage,
                Op::TypeAccelerationStructureKHR => Ty::AccelerationStructure,
                Op::Constant | Op::SpecConstant => {
                    this.constants.insert(id, w(0));
                    continue;
                }
                Op::Variable => {
                    this.variables.push(i);
                    continue;
                }
                _ => Ty::Other,
            };
            this.types.insert(id, ty);
        }
        this
    }

    /// The size of a type in bytes as laid out in a buffer (a runtime
    /// array counts as empty).
    fn size(&self, ty: u32) -> usize {
        match self.types.get(&ty) {
            Some(Ty::Scalar(n)) => *n,
            Some(Ty::Vector(c, n)) => self.size(*c) * *n as usize,
            Some(Ty::Array(e, len)) => {
                let len = self.constants.get(len).copied().unwrap_or(0) as usize;
                self.stride.get(&ty).map_or_else(|| self.size(*e), |&s| s as usize) * len
            }
            Some(Ty::Struct(members)) => {
                let ends = members
                    .iter()
                    .enumerate()
                    .map(|(k, m)| self.offset.get(&(ty, k as u32)).copied().unwrap_or(0) + self.size(*m));
                ends.max().unwrap_or(0)
            }
            _ => 0,
        }
    }

    /// Adds every struct with an explicit layout inside `ty` to `out`;
    /// `stride` is the array stride when `ty` is an array element.
    fn collect_structs(&self, ty: u32, stride: Option<usize>, out: &mut BTreeMap<String, StructLayout>) {
        match self.types.get(&ty) {
            Some(Ty::Array(e, _)) | Some(Ty::RuntimeArray(e)) => {
                self.collect_structs(*e, self.stride.get(&ty).map(|&s| s as usize), out)
            }
            Some(Ty::Struct(members)) => {
                let laid_out: Option<Vec<Member>> = members
                    .iter()
                    .enumerate()
                    .map(|(k, &m)| {
                        Some(Member {
                            name: self.member_names.get(&(ty, k as u32)).cloned().unwrap_or_default(),
                            offset: *self.offset.get(&(ty, k as u32))?,
                            size: self.size(m),
                        })
                    })
                    .collect();
                if let (Some(name), Some(members)) = (self.names.get(&ty), laid_out) {
                    let layout = StructLayout { name: name.clone(), members, stride };
                    match out.get_mut(name) {
                        // Keep the stride where one use of the struct gives it.
                        Some(old) if old.stride.is_none() => *old = layout,
                        Some(_) => {}
                        None => {
                            out.insert(name.clone(), layout);
                        }
                    }
                }
                for &m in members {
                    self.collect_structs(m, None, out);
                }
            }
            _ => {}
        }
    }
}

/// A host struct's fields, for [`check_layout`]: name (snake_case), byte
/// offset and size. Made by [`host_layout!`](crate::host_layout).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostLayout {
    /// The Rust type's name.
    pub name: &'static str,
    /// The GLSL struct it mirrors.
    pub glsl: &'static str,
    /// `size_of` the type.
    pub size: usize,
    /// Every field: name, offset, size.
    pub fields: Vec<(&'static str, usize, usize)>,
}

/// The size of the field that `get` borrows (for [`host_layout!`](crate::host_layout)).
pub fn field_size<T, F>(_get: impl Fn(&T) -> &F) -> usize {
    std::mem::size_of::<F>()
}

/// The [`HostLayout`] of a `#[repr(C)]` struct: `host_layout!(Type as
/// "GlslName" { field, ... })`, every field in declaration order.
#[macro_export]
macro_rules! host_layout {
    ($ty:ty as $glsl:literal { $($field:ident),* $(,)? }) => {
        $crate::vk::reflect::HostLayout {
            name: stringify!($ty),
            glsl: $glsl,
            size: ::std::mem::size_of::<$ty>(),
            fields: vec![$((
                stringify!($field),
                ::std::mem::offset_of!($ty, $field),
                $crate::vk::reflect::field_size(|v: &$ty| &v.$field),
            )),*],
        }
    };
}

pub use super::naming::snake_case;

/// Checks a host struct against the shader's layout of the same struct,
/// member by member: the same names in the same order (GLSL `camelCase` as
/// Rust `snake_case`), offsets and sizes, and the same total size.
pub fn check_layout(host: &HostLayout, shader: &StructLayout) -> Result<(), InterfaceError> {
    let err = |what: String| InterfaceError::Layout { glsl: host.glsl.into(), host: host.name.into(), what };
    let shader_names: Vec<String> = shader.members.iter().map(|m| snake_case(&m.name)).collect();
    let host_names: Vec<&str> = host.fields.iter().map(|f| f.0).collect();
    if shader_names != host_names {
        return Err(err(format!("members {shader_names:?} in the shader, fields {host_names:?} on the host")));
    }
    for (m, &(field, offset, size)) in shader.members.iter().zip(&host.fields) {
        if (m.offset, m.size) != (offset, size) {
            return Err(err(format!(
                "{field}: offset {} and size {} in the shader, offset {offset} and size {size} on the host",
                m.offset, m.size
            )));
        }
    }
    if shader.size() != host.size {
        return Err(err(format!("{} bytes in the shader, {} on the host", shader.size(), host.size)));
    }
    Ok(())
}
