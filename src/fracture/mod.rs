//! Fracture measurement beside the systems: what a measurement is asked for and returns
//! (`plan`), the 2D interaction integral, the 3D front frames and tube integrals, and the
//! eta estimate of J.

pub mod eta;
pub mod front;
pub mod front_integral;
pub mod interaction;
pub mod plan;
