//! Spatial dimension: one code path for 2D and 3D.
//!
//! Systems are generic over [`Dim`]; the two instances [`D2`] and [`D3`] supply the vector and
//! matrix types (glam `DVec2`/`DMat2`, `DVec3`/`DMat3`) and the few operations that differ.
//! Grid indices are always `[usize; 3]` with a unit third axis in 2D, so stencil loops are
//! written once.

use crate::base::columnar::Columnar;
use crate::base::geometry::{Element, Point, Segment, Triangle};
use crate::base::sym::{Sym2, Sym3, SymTensor};
use glam::{DMat2, DMat3, DVec2, DVec3};
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign};

/// A spatial dimension (2 or 3) with its vector and matrix types.
pub trait Dim: Copy + Clone + Send + Sync + Debug + Default + 'static {
    /// Number of spatial axes.
    const D: usize;
    /// Number of P2G colour classes (2^D).
    const COLOURS: usize;
    /// Position, velocity and force vectors.
    type Vec: Copy
        + Send
        + Sync
        + Debug
        + PartialEq
        + Add<Output = Self::Vec>
        + Sub<Output = Self::Vec>
        + Mul<f64, Output = Self::Vec>
        + Neg<Output = Self::Vec>
        + AddAssign
        + SubAssign
        + MulAssign<f64>
        + Index<usize, Output = f64>
        + IndexMut<usize>
        + Point
        + Columnar;
    /// Velocity-gradient matrices, column-major: `m.col(j)[i] = dv_i/dx_j`.
    type Mat: Copy
        + Send
        + Sync
        + Debug
        + Add<Output = Self::Mat>
        + Mul<f64, Output = Self::Mat>
        + Columnar;
    /// Stress as stored on particles: [`Sym2`] in 2D, [`Sym3`] in 3D.
    type Sym: SymTensor;
    /// Crack element: a [`Segment`] in 2D, a [`Triangle`] in 3D.
    type Elem: Element<Vec = Self::Vec>;

    /// The zero vector.
    fn zero() -> Self::Vec;
    /// The zero matrix.
    fn mat_zero() -> Self::Mat;
    /// Vector from a slice of exactly `D` values.
    fn from_slice(s: &[f64]) -> Self::Vec;
    /// Vector padded to three components (z = 0 in 2D), for output.
    fn to_xyz(v: Self::Vec) -> [f64; 3];
    /// Dot product.
    fn dot(a: Self::Vec, b: Self::Vec) -> f64;
    /// Outer product `a ⊗ b` (entry (i, j) = a_i b_j).
    fn outer(a: Self::Vec, b: Self::Vec) -> Self::Mat;
    /// `l + a ⊗ (q x̂) + b ⊗ (0, gy[, gz])`: one stencil row's share of a velocity gradient,
    /// without the products by the zero entries (`gz` unused in 2D).
    fn add_row(l: Self::Mat, a: Self::Vec, q: f64, b: Self::Vec, gy: f64, gz: f64) -> Self::Mat;
    /// Matrix entry (i, j).
    fn entry(m: &Self::Mat, i: usize, j: usize) -> f64;
    /// Symmetric part of a velocity gradient embedded in 3x3 (zz = yz = xz = 0 in 2D).
    fn sym_part(l: &Self::Mat) -> Sym3;
    /// In-plane part of `sigma · g` (the traction-like product in the internal force).
    fn stress_dot(s: &Self::Sym, g: Self::Vec) -> Self::Vec;
    /// `sigma · (0, gy[, gz])`, without the products by the zero entry (`gz` unused in 2D).
    fn stress_dot_yz(s: &Self::Sym, gy: f64, gz: f64) -> Self::Vec;
    /// Cross product of position and momentum, padded to 3 components (z only in 2D).
    fn cross(r: Self::Vec, p: Self::Vec) -> [f64; 3];
    /// The unit vector along x.
    fn unit_x() -> Self::Vec;
    /// Gradient of the tensor-product shape function for stencil offsets (i, j, k).
    fn grad(w: &[[f64; 3]; 3], dw: &[[f64; 3]; 3], i: usize, j: usize, k: usize) -> Self::Vec;
}

/// Two dimensions (plane strain or plane stress).
#[derive(Clone, Copy, Debug, Default)]
pub struct D2;

/// Three dimensions.
#[derive(Clone, Copy, Debug, Default)]
pub struct D3;

impl Dim for D2 {
    const D: usize = 2;
    const COLOURS: usize = 4;
    type Vec = DVec2;
    type Mat = DMat2;
    type Sym = Sym2;
    type Elem = Segment;

    #[inline(always)]
    fn zero() -> DVec2 {
        DVec2::ZERO
    }
    #[inline(always)]
    fn mat_zero() -> DMat2 {
        DMat2::ZERO
    }
    fn from_slice(s: &[f64]) -> DVec2 {
        DVec2::new(s[0], s[1])
    }
    fn to_xyz(v: DVec2) -> [f64; 3] {
        [v.x, v.y, 0.0]
    }
    #[inline(always)]
    fn dot(a: DVec2, b: DVec2) -> f64 {
        a.dot(b)
    }
    #[inline(always)]
    fn outer(a: DVec2, b: DVec2) -> DMat2 {
        DMat2::from_cols(a * b.x, a * b.y)
    }
    #[inline(always)]
    fn add_row(l: DMat2, a: DVec2, q: f64, b: DVec2, gy: f64, _gz: f64) -> DMat2 {
        DMat2::from_cols(l.x_axis + a * q, l.y_axis + b * gy)
    }
    #[inline(always)]
    fn entry(m: &DMat2, i: usize, j: usize) -> f64 {
        m.col(j)[i]
    }
    #[inline(always)]
    fn sym_part(l: &DMat2) -> Sym3 {
        Sym3 {
            xx: l.x_axis.x,
            yy: l.y_axis.y,
            zz: 0.0,
            yz: 0.0,
            xz: 0.0,
            xy: 0.5 * (l.y_axis.x + l.x_axis.y),
        }
    }
    #[inline(always)]
    fn stress_dot(s: &Sym2, g: DVec2) -> DVec2 {
        DVec2::new(s.xx * g.x + s.xy * g.y, s.xy * g.x + s.yy * g.y)
    }
    #[inline(always)]
    fn stress_dot_yz(s: &Sym2, gy: f64, _gz: f64) -> DVec2 {
        DVec2::new(s.xy * gy, s.yy * gy)
    }
    fn cross(r: DVec2, p: DVec2) -> [f64; 3] {
        [0.0, 0.0, r.perp_dot(p)]
    }
    #[inline(always)]
    fn unit_x() -> DVec2 {
        DVec2::X
    }
    #[inline(always)]
    fn grad(w: &[[f64; 3]; 3], dw: &[[f64; 3]; 3], i: usize, j: usize, _k: usize) -> DVec2 {
        DVec2::new(dw[0][i] * w[1][j], w[0][i] * dw[1][j])
    }
}

impl Dim for D3 {
    const D: usize = 3;
    const COLOURS: usize = 8;
    type Vec = DVec3;
    type Mat = DMat3;
    type Sym = Sym3;
    type Elem = Triangle;

    #[inline(always)]
    fn zero() -> DVec3 {
        DVec3::ZERO
    }
    #[inline(always)]
    fn mat_zero() -> DMat3 {
        DMat3::ZERO
    }
    fn from_slice(s: &[f64]) -> DVec3 {
        DVec3::new(s[0], s[1], s[2])
    }
    fn to_xyz(v: DVec3) -> [f64; 3] {
        v.to_array()
    }
    #[inline(always)]
    fn dot(a: DVec3, b: DVec3) -> f64 {
        a.dot(b)
    }
    #[inline(always)]
    fn outer(a: DVec3, b: DVec3) -> DMat3 {
        DMat3::from_cols(a * b.x, a * b.y, a * b.z)
    }
    #[inline(always)]
    fn add_row(l: DMat3, a: DVec3, q: f64, b: DVec3, gy: f64, gz: f64) -> DMat3 {
        DMat3::from_cols(l.x_axis + a * q, l.y_axis + b * gy, l.z_axis + b * gz)
    }
    #[inline(always)]
    fn entry(m: &DMat3, i: usize, j: usize) -> f64 {
        m.col(j)[i]
    }
    #[inline(always)]
    fn sym_part(l: &DMat3) -> Sym3 {
        Sym3 {
            xx: l.x_axis.x,
            yy: l.y_axis.y,
            zz: l.z_axis.z,
            yz: 0.5 * (l.z_axis.y + l.y_axis.z),
            xz: 0.5 * (l.z_axis.x + l.x_axis.z),
            xy: 0.5 * (l.y_axis.x + l.x_axis.y),
        }
    }
    #[inline(always)]
    fn stress_dot(s: &Sym3, g: DVec3) -> DVec3 {
        DVec3::new(
            s.xx * g.x + s.xy * g.y + s.xz * g.z,
            s.xy * g.x + s.yy * g.y + s.yz * g.z,
            s.xz * g.x + s.yz * g.y + s.zz * g.z,
        )
    }
    #[inline(always)]
    fn stress_dot_yz(s: &Sym3, gy: f64, gz: f64) -> DVec3 {
        DVec3::new(
            s.xy * gy + s.xz * gz,
            s.yy * gy + s.yz * gz,
            s.yz * gy + s.zz * gz,
        )
    }
    fn cross(r: DVec3, p: DVec3) -> [f64; 3] {
        r.cross(p).to_array()
    }
    #[inline(always)]
    fn unit_x() -> DVec3 {
        DVec3::X
    }
    #[inline(always)]
    fn grad(w: &[[f64; 3]; 3], dw: &[[f64; 3]; 3], i: usize, j: usize, k: usize) -> DVec3 {
        DVec3::new(
            dw[0][i] * w[1][j] * w[2][k],
            w[0][i] * dw[1][j] * w[2][k],
            w[0][i] * w[1][j] * dw[2][k],
        )
    }
}
