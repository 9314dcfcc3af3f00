//! The CPU model: the exact f64 geometry and its reference intersection,
//! textures and the environment, the scene (parsed from TOML), the f64
//! twins of the GPU's sampling code, and the covariance-tracing oracle.

pub mod covariance;
pub mod geometry;
pub mod sampling;
pub mod scene;
pub mod texture;
