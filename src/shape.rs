//! Grid shape functions: linear, uGIMP and quadratic B-spline, with gradients.
//!
//! Weights are tensor products of 1D functions, evaluated once per particle into a
//! [`Stencil`] of at most 3 nodes per axis.

use crate::dim::Dim;
use crate::grid::GridGeom;
use serde::{Deserialize, Serialize};

/// Which shape function maps particles to the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    /// Classic MPM tent functions (2 nodes per axis).
    Linear,
    /// Undeformed generalized interpolation material point (Bardenhagen & Kober 2004).
    #[default]
    Ugimp,
    /// Quadratic B-spline (3 nodes per axis).
    Bspline,
}

impl ShapeKind {
    /// How far the support reaches beyond the particle position, in units of the cell size
    /// (`l` is the particle half-width over the cell size, used by uGIMP).
    pub fn reach(self, l: f64) -> f64 {
        match self {
            ShapeKind::Linear => 0.0,
            ShapeKind::Ugimp => l,
            ShapeKind::Bspline => 0.5,
        }
    }

    /// 1D weights on one axis: first node index, weights and d/dx for up to three nodes.
    /// `xi` is the position in cell units from the grid origin, `l` the half-width in cell
    /// units, `inv_h` the inverse cell size. Callers ensure the stencil lies in the grid.
    #[inline(always)]
    pub fn axis(self, xi: f64, l: f64, inv_h: f64) -> (usize, usize, [f64; 3], [f64; 3]) {
        match self {
            ShapeKind::Linear => {
                let base = xi.floor();
                let f = xi - base;
                (base as usize, 2, [1.0 - f, f, 0.0], [-inv_h, inv_h, 0.0])
            }
            ShapeKind::Ugimp => {
                let base = (xi - l).floor();
                let mut w = [0.0; 3];
                let mut dw = [0.0; 3];
                for a in 0..3 {
                    let r = xi - (base + a as f64);
                    let (s, g) = gimp_1d(r, l);
                    w[a] = s;
                    dw[a] = g * inv_h;
                }
                (base as usize, 3, w, dw)
            }
            ShapeKind::Bspline => {
                let base = (xi - 0.5).floor();
                let f = xi - base;
                let (a, b, c) = (1.5 - f, f - 1.0, f - 0.5);
                (
                    base as usize,
                    3,
                    [0.5 * a * a, 0.75 - b * b, 0.5 * c * c],
                    [-a * inv_h, -2.0 * b * inv_h, c * inv_h],
                )
            }
        }
    }
}

/// uGIMP weight and its derivative (per cell unit) at signed distance `r` (cell units) from
/// a node, particle half-width `l` (Bardenhagen & Kober 2004, Eq. 39 in 1D).
#[inline(always)]
fn gimp_1d(r: f64, l: f64) -> (f64, f64) {
    let d = r.abs();
    let sign = r.signum();
    if d < l {
        (1.0 - (r * r + l * l) / (2.0 * l), -r / l)
    } else if d < 1.0 - l {
        (1.0 - d, -sign)
    } else if d < 1.0 + l {
        let e = 1.0 + l - d;
        (e * e / (4.0 * l), -sign * e / (2.0 * l))
    } else {
        (0.0, 0.0)
    }
}

/// Shape-function values and gradients of one particle on its stencil nodes.
#[derive(Clone, Copy, Debug)]
pub struct Stencil {
    /// First node index per axis.
    pub base: [usize; 3],
    /// Nodes per axis (1 on the unused third axis in 2D).
    pub n: [usize; 3],
    /// 1D weights per axis.
    pub w: [[f64; 3]; 3],
    /// 1D derivatives per axis (1/m).
    pub dw: [[f64; 3]; 3],
}

impl Stencil {
    /// Evaluates the stencil at `x` with particle half-width `half` (m, used by uGIMP only).
    #[inline(always)]
    pub fn new<D: Dim>(shape: ShapeKind, geom: &GridGeom<D>, x: D::Vec, half: D::Vec) -> Self {
        let mut st = Stencil {
            base: [0; 3],
            n: [1; 3],
            w: [[1.0, 0.0, 0.0]; 3],
            dw: [[0.0; 3]; 3],
        };
        for a in 0..D::D {
            let xi = (x[a] - geom.origin[a]) * geom.inv_h[a];
            let (b, n, w, dw) = shape.axis(xi, half[a] * geom.inv_h[a], geom.inv_h[a]);
            st.base[a] = b;
            st.n[a] = n;
            st.w[a] = w;
            st.dw[a] = dw;
        }
        st
    }

    /// Calls `f(node, weight, gradient)` for every node of the stencil, in a fixed order.
    #[inline(always)]
    pub fn for_each<D: Dim>(&self, stride: &[usize; 3], mut f: impl FnMut(usize, f64, D::Vec)) {
        for k in 0..self.n[2] {
            for j in 0..self.n[1] {
                let row = self.base[0]
                    + stride[1] * (self.base[1] + j)
                    + stride[2] * (self.base[2] + k);
                let wjk = self.w[1][j] * self.w[2][k];
                for i in 0..self.n[0] {
                    f(
                        row + i,
                        self.w[0][i] * wjk,
                        D::grad(&self.w, &self.dw, i, j, k),
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Partition of unity, zero gradient sum and linear completeness hold for every kind.
    #[test]
    fn partition_of_unity_and_linear_reproduction() {
        for shape in [ShapeKind::Linear, ShapeKind::Ugimp, ShapeKind::Bspline] {
            for s in 0..200 {
                let xi = 3.0 + s as f64 * 0.0137;
                let (base, n, w, dw) = shape.axis(xi, 0.25, 2.0);
                let sum: f64 = w[..n].iter().sum();
                let dsum: f64 = dw[..n].iter().sum();
                let first: f64 = (0..n).map(|a| w[a] * (base + a) as f64).sum();
                let dfirst: f64 = (0..n).map(|a| dw[a] * (base + a) as f64).sum();
                assert!((sum - 1.0).abs() < 1e-14, "{shape:?} sum {sum}");
                assert!(dsum.abs() < 1e-13, "{shape:?} dsum {dsum}");
                assert!((first - xi).abs() < 1e-13, "{shape:?} x {first} vs {xi}");
                assert!((dfirst - 2.0).abs() < 1e-12, "{shape:?} dx {dfirst}");
            }
        }
    }
}
