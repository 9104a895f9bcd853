//! Fissure: a data-oriented material point method (MPM) kernel for dynamic fracture.
//!
//! Particles and grid nodes live in struct-of-arrays stores inside a [`world::World`];
//! ordered systems (in `systems/`, one file each) advance it; one code path serves 2D and 3D
//! through the [`dim::Dim`] trait. SI units and f64 throughout.
#![warn(missing_docs)]

pub mod bodies;
pub mod columnar;
pub mod crack;
pub mod dim;
pub mod disjoint;
pub mod error;
pub mod eta;
pub mod fracture;
pub mod front;
pub mod front_integral;
pub mod geometry;
pub mod grid;
pub mod growth;
pub mod interaction;
pub mod loads;
pub mod material;
pub mod measure;
pub mod near_tip;
pub mod output;
pub mod particles;
pub mod plastic;
pub mod run;
pub mod scenario;
pub mod schedule;
pub mod shape;
pub mod snapshot;
pub mod sweep;
pub mod sym;
pub mod tiles;
pub mod timefn;
mod warm;
pub mod world;

#[path = "../systems/mod.rs"]
pub mod systems;
