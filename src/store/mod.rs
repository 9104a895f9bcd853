//! The component stores, struct of arrays: particles, grid nodes, spatial tiles, cracks,
//! and the World that owns them.

pub mod crack;
pub mod disjoint;
pub mod grid;
pub mod mirror;
pub mod particles;
pub mod tiles;
pub mod world;
