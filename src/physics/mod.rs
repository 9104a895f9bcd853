//! What the stores are made of and what acts on them: shape functions, materials (elastic
//! and J2 plastic), bodies' geometry, loads, boundary conditions and time functions, the
//! closed-form near-tip fields, and the laws cracks grow by.

pub mod bodies;
pub mod growth;
pub mod loads;
pub mod material;
pub mod near_tip;
pub mod plastic;
pub mod shape;
pub mod timefn;
