//! Passes that only tests use: the texture probe, which runs the render
//! shader's filtered lookups on given footprints (`tests/render/texfilter_gpu.rs`
//! compares them with the CPU's). (The ray probe, `passes::probe`, also
//! serves `make bench`.)

pub mod texprobe;
