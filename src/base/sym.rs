//! Symmetric 3x3 tensors (stress, strain): [`Sym3`] holds all six components; the particle
//! stress column holds [`SymTensor`]s sized to the dimension ([`Sym2`] in 2D, four
//! components, since yz and xz are zero in plane strain and plane stress).

use crate::base::columnar::{Columnar, Scalar};
use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Mul};

/// A symmetric tensor stored with only the components its dimension can have, converted to
/// and from the full [`Sym3`] where it is computed with.
pub trait SymTensor: Copy + Default + Debug + PartialEq + Send + Sync + Columnar {
    /// The full tensor.
    fn to_sym3(&self) -> Sym3;
    /// The components of `s` this type stores (in 2D, yz and xz are dropped: they are zero
    /// in plane strain and plane stress).
    fn from_sym3(s: Sym3) -> Self;
    /// Largest absolute component.
    fn max_abs(&self) -> f64 {
        self.to_sym3().max_abs()
    }
}

/// A 2D stress: the in-plane components and zz (sigma_zz is non-zero in plane strain);
/// yz = xz = 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, Pod, Zeroable)]
#[repr(C)]
pub struct Sym2 {
    /// xx component.
    pub xx: f64,
    /// yy component.
    pub yy: f64,
    /// zz component.
    pub zz: f64,
    /// xy component.
    pub xy: f64,
}

impl Columnar for Sym2 {
    const SCALAR: Scalar = Scalar::F64;
}

impl SymTensor for Sym2 {
    #[inline(always)]
    fn to_sym3(&self) -> Sym3 {
        Sym3 {
            xx: self.xx,
            yy: self.yy,
            zz: self.zz,
            yz: 0.0,
            xz: 0.0,
            xy: self.xy,
        }
    }
    #[inline(always)]
    fn from_sym3(s: Sym3) -> Sym2 {
        Sym2 {
            xx: s.xx,
            yy: s.yy,
            zz: s.zz,
            xy: s.xy,
        }
    }
}

impl SymTensor for Sym3 {
    #[inline(always)]
    fn to_sym3(&self) -> Sym3 {
        *self
    }
    #[inline(always)]
    fn from_sym3(s: Sym3) -> Sym3 {
        s
    }
}

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

impl Columnar for Sym3 {
    const SCALAR: Scalar = Scalar::F64;
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

    /// The isotropic tensor I.
    #[inline(always)]
    pub fn identity() -> Sym3 {
        Sym3 {
            xx: 1.0,
            yy: 1.0,
            zz: 1.0,
            ..Sym3::default()
        }
    }

    /// The deviatoric part `a - tr(a)/3 I`.
    #[inline(always)]
    pub fn deviator(&self) -> Sym3 {
        let p = self.trace() / 3.0;
        Sym3 {
            xx: self.xx - p,
            yy: self.yy - p,
            zz: self.zz - p,
            ..*self
        }
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
