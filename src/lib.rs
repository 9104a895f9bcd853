//! Fissure: a data-oriented material point method (MPM) kernel for fracture with explicit
//! cracks.
//!
//! Particles, grid nodes and crack vertices live in struct-of-arrays stores inside a
//! [`store::world::World`]; ordered systems (in `systems/`, one file each) advance it; one
//! code path serves 2D and 3D through the [`base::dim::Dim`] trait. SI units and f64
//! throughout. The modules, by role, from the ground up: `base` (algebra and geometry),
//! `store` (the component stores), `physics` (shape functions, materials, loads),
//! `fracture` (J, K and growth laws), `record` (probes, history, expects), `systems` and
//! `pipeline` (the step), `io` (scenarios, snapshots, outputs) and `app` (the run loop and
//! sweeps the launcher drives).
#![warn(missing_docs)]

pub mod app;
pub mod base;
pub mod fracture;
pub mod io;
pub mod physics;
pub mod pipeline;
pub mod ranks;
pub mod record;
pub mod store;

#[path = "../systems/mod.rs"]
pub mod systems;
