//! External particle forces and prescribed grid velocities.

use crate::dim::Dim;
use crate::timefn::TimeFn;

/// Forces on a fixed set of particles, scaled by a time function.
#[derive(Clone, Debug)]
pub struct Load<D: Dim> {
    /// Loaded particles.
    pub particles: Vec<u32>,
    /// Force on each of `particles` at full load (N).
    pub forces: Vec<D::Vec>,
    /// Time multiplier.
    pub time: TimeFn,
}

/// Stress (xx, yy, xy) of the leading near-tip term for a crack along theta = +-pi, at
/// polar position (r, theta) about the tip (Williams 1957, Irwin 1957; the closed form in
/// REFERENCE.md). Independent of the material and of plane strain or stress.
pub fn williams_stress(k1: f64, k2: f64, r: f64, theta: f64) -> [f64; 3] {
    let a = 1.0 / (2.0 * std::f64::consts::PI * r).sqrt();
    let (s, c) = (0.5 * theta).sin_cos();
    let (s3, c3) = (1.5 * theta).sin_cos();
    [
        a * (k1 * c * (1.0 - s * s3) - k2 * s * (2.0 + c * c3)),
        a * (k1 * c * (1.0 + s * s3) + k2 * s * c * c3),
        a * (k1 * s * c * c3 + k2 * c * (1.0 - s * s3)),
    ]
}

/// Prescribed velocity components on a fixed set of grid nodes (fixed supports, symmetry
/// planes, moving grips).
#[derive(Clone, Debug)]
pub struct VelocityBc<D: Dim> {
    /// Constrained nodes.
    pub nodes: Vec<u32>,
    /// Which components are prescribed.
    pub axes: [bool; 3],
    /// Prescribed velocity at full scale (m/s).
    pub velocity: D::Vec,
    /// Time multiplier on `velocity`.
    pub time: TimeFn,
}

impl<D: Dim> VelocityBc<D> {
    /// Prescribed velocity component `a` at time `t`.
    #[inline(always)]
    pub fn value(&self, a: usize, t: f64) -> f64 {
        self.velocity[a] * self.time.at(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The faces theta = +-pi carry no traction (s_yy = s_xy = 0) and, ahead of the tip,
    /// s_yy = K_I / sqrt(2 pi r) and s_xy = K_II / sqrt(2 pi r).
    #[test]
    fn williams_faces_are_free_and_ligament_carries_k() {
        let (k1, k2, r) = (2.0e6, -0.7e6, 1e-3);
        let a = 1.0 / (2.0 * std::f64::consts::PI * r).sqrt();
        let ahead = williams_stress(k1, k2, r, 0.0);
        assert!((ahead[1] - k1 * a).abs() < 1e-9 * k1 * a);
        assert!((ahead[2] - k2 * a).abs() < 1e-9 * k1 * a);
        for t in [std::f64::consts::PI, -std::f64::consts::PI] {
            let face = williams_stress(k1, k2, r, t);
            assert!(face[1].abs() < 1e-9 * k1 * a && face[2].abs() < 1e-9 * k1 * a);
        }
    }
}
