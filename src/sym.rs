//! Symmetric 3x3 tensors (stress, strain), stored as six components in 2D and 3D alike.

use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign, Mul};

/// A symmetric 3x3 tensor; shear entries are tensor (not engineering) components.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, Pod, Zeroable)]
#[repr(C)]
pub struct Sym3 {
    /// xx component.
    pub xx: f64,
    /// yy component.
    pub yy: f64,
    /// zz component.
    pub zz: f64,
    /// yz component.
    pub yz: f64,
    /// xz component.
    pub xz: f64,
    /// xy component.
    pub xy: f64,
}

impl Sym3 {
    /// Trace.
    #[inline(always)]
    pub fn trace(&self) -> f64 {
        self.xx + self.yy + self.zz
    }

    /// Double contraction `a : b`.
    #[inline(always)]
    pub fn ddot(&self, b: &Sym3) -> f64 {
        self.xx * b.xx
            + self.yy * b.yy
            + self.zz * b.zz
            + 2.0 * (self.yz * b.yz + self.xz * b.xz + self.xy * b.xy)
    }

    /// Components in the order xx, yy, zz, yz, xz, xy.
    pub fn to_array(&self) -> [f64; 6] {
        [self.xx, self.yy, self.zz, self.yz, self.xz, self.xy]
    }

    /// Largest absolute component.
    pub fn max_abs(&self) -> f64 {
        self.to_array().iter().fold(0.0, |m, c| m.max(c.abs()))
    }
}

impl Add for Sym3 {
    type Output = Sym3;
    #[inline(always)]
    fn add(self, b: Sym3) -> Sym3 {
        Sym3 {
            xx: self.xx + b.xx,
            yy: self.yy + b.yy,
            zz: self.zz + b.zz,
            yz: self.yz + b.yz,
            xz: self.xz + b.xz,
            xy: self.xy + b.xy,
        }
    }
}

impl AddAssign for Sym3 {
    #[inline(always)]
    fn add_assign(&mut self, b: Sym3) {
        *self = *self + b;
    }
}

impl Mul<f64> for Sym3 {
    type Output = Sym3;
    #[inline(always)]
    fn mul(self, s: f64) -> Sym3 {
        Sym3 {
            xx: self.xx * s,
            yy: self.yy * s,
            zz: self.zz * s,
            yz: self.yz * s,
            xz: self.xz * s,
            xy: self.xy * s,
        }
    }
}
