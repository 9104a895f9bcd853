//! The ground floor: the dimension trait and its vectors and tensors, geometry and crack
//! elements, the column layout of stored types, error types. Imports
//! nothing above it.

pub mod columnar;
pub mod dim;
pub mod error;
pub mod exact_sum;
pub mod geometry;
pub mod sym;
