//! What the host shares with the shaders: binding numbers, specialisation
//! constant ids and enum values (`shader_interface`, turned into GLSL
//! #defines by build.rs), and the SPIR-V build.rs compiled (`shaders`).

pub mod shader_interface;
pub mod shaders;
