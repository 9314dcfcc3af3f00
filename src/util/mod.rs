//! Leaf libraries every layer may use: files written all or nothing, a
//! stable FNV-1a hash, and progress bars.

pub mod files;
pub mod hash;
pub mod progress;
