//! External particle forces and prescribed grid velocities.

use crate::base::dim::Dim;
use crate::physics::timefn::TimeFn;
use num_complex::Complex64;

/// Forces on a fixed set of particles, scaled by a time function.
#[derive(Clone, Debug)]
pub struct Load<D: Dim> {
    /// Loaded particles (split across ranks: this rank's index, or `ABSENT`).
    pub particles: Vec<u32>,
    /// Split across ranks: the loaded particles' ids in the whole scene (empty on one rank).
    pub ids: Vec<u32>,
    /// Force on each of `particles` at full load (N).
    pub forces: Vec<D::Vec>,
    /// Time multiplier.
    pub time: TimeFn,
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
    /// The force each node's support exerted on the body over the last step (N; in 2D for
    /// the scene's thickness), in the prescribed components: m (a_prescribed - a_free),
    /// summed over the node's crack fields. Zero before the first step.
    pub reaction: Vec<D::Vec>,
}

impl<D: Dim> VelocityBc<D> {
    /// Prescribed velocity component `a` at time `t`.
    #[inline(always)]
    pub fn value(&self, a: usize, t: f64) -> f64 {
        self.velocity[a] * self.time.at(t)
    }
}

/// Stress (xx, yy, xy) of a crack from x = -a to a along the x axis in an infinite plate
/// under remote stress `remote` (xx, yy, xy), at (x, y) (Westergaard 1939, the complex
/// potentials Z_I = s_yy z / sqrt(z^2 - a^2) and Z_II = s_xy z / sqrt(z^2 - a^2) in the form
/// of Tada, Paris & Irwin (2000) section 1; s_xx - s_yy added as a uniform stress parallel to
/// the crack). K_I = s_yy sqrt(pi a), K_II = s_xy sqrt(pi a). None on the crack itself.
pub fn centre_crack_stress(remote: [f64; 3], a: f64, x: f64, y: f64) -> Option<[f64; 3]> {
    let z = Complex64::new(x, y);
    // sqrt(z - a) sqrt(z + a): analytic off the cut [-a, a] and ~ z far away.
    let root = (z - a).sqrt() * (z + a).sqrt();
    if y == 0.0 && x.abs() <= a || root.norm() == 0.0 {
        return None;
    }
    let shape = z / root;
    let dshape = -a * a / (root * root * root);
    let (zi, dzi) = (shape * remote[1], dshape * remote[1]);
    let (zii, dzii) = (shape * remote[2], dshape * remote[2]);
    Some([
        zi.re - y * dzi.im + 2.0 * zii.im + y * dzii.re + remote[0] - remote[1],
        zi.re + y * dzi.im - y * dzii.re,
        -y * dzi.re + zii.re - y * dzii.im,
    ])
}

/// Rotates a plane stress (xx, yy, xy) from axes turned by `angle` (radians) to the global
/// axes: R s R^T.
pub fn rotate_stress(s: [f64; 3], angle: f64) -> [f64; 3] {
    let (sn, cs) = angle.sin_cos();
    [
        cs * cs * s[0] + sn * sn * s[1] - 2.0 * cs * sn * s[2],
        sn * sn * s[0] + cs * cs * s[1] + 2.0 * cs * sn * s[2],
        cs * sn * (s[0] - s[1]) + (cs * cs - sn * sn) * s[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Far from the crack the centre-crack field is the remote stress; the faces are free;
    /// near a tip it is the Williams field with K_I = s_yy sqrt(pi a), K_II = s_xy sqrt(pi a)
    /// (checked around the right tip, where theta is measured as for Williams).
    #[test]
    fn centre_crack_field_limits() {
        let (remote, a) = ([30e6, 100e6, 40e6], 0.01);
        let far = centre_crack_stress(remote, a, 300.0, -200.0).unwrap();
        for (f, r) in far.iter().zip(remote) {
            assert!((f - r).abs() < 1e-5 * 100e6, "{far:?}");
        }
        for x in [-0.009, -0.003, 0.0, 0.005, 0.0099] {
            for y in [1e-300, -1e-300] {
                let s = centre_crack_stress(remote, a, x, y).unwrap();
                assert!(s[1].abs() < 1e-6 && s[2].abs() < 1e-6, "face at {x}: {s:?}");
            }
        }
        let (k1, k2) = (100e6 * (PI * a).sqrt(), 40e6 * (PI * a).sqrt());
        let r = 1e-7;
        for t in [-3.0, -2.0, -1.0, 0.0, 0.5, 1.5, 2.5, 3.1] {
            let s = centre_crack_stress(remote, a, a + r * f64::cos(t), r * f64::sin(t)).unwrap();
            // Williams plus the T-stress s_xx - s_yy; the next terms vanish like sqrt(r).
            let mut w = crate::physics::near_tip::stress(k1, k2, r, t);
            w[0] += remote[0] - remote[1];
            for (s, w) in s.iter().zip(w) {
                assert!(
                    (s - w).abs() < 1e-4 * k1 / (2.0 * PI * r).sqrt(),
                    "{t}: {s} vs {w}"
                );
            }
        }
        assert!(centre_crack_stress(remote, a, 0.004, 0.0).is_none());
    }

    /// Rotating by a quarter turn swaps the normal stresses and flips the shear.
    #[test]
    fn quarter_turn_swaps_axes() {
        let s = rotate_stress([1.0, 2.0, 3.0], 0.5 * PI);
        assert!((s[0] - 2.0).abs() < 1e-12 && (s[1] - 1.0).abs() < 1e-12);
        assert!((s[2] + 3.0).abs() < 1e-12);
    }
}
