//! The command-line commands, one module per group; `main.rs` parses and
//! dispatches.

pub(crate) mod bench;
pub(crate) mod common;
pub(crate) mod devices;
pub(crate) mod export;
pub(crate) mod farm;
pub(crate) mod images;
pub(crate) mod render;
#[cfg(feature = "viewer")]
pub(crate) mod view;
