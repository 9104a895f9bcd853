//! The systems, one file each, in pipeline order. Each is a plain function over the World.

pub mod bin;
pub mod classify;
pub mod contact;
pub mod crack_advect;
pub mod fracture;
pub mod fracture_front;
pub mod g2p;
pub mod grid_update;
pub mod grow;
pub mod grow_front;
pub mod p2g;
pub mod stress;
pub mod stress_bin;
pub mod stress_force;
