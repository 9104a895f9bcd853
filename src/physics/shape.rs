//! Grid shape functions: linear, uGIMP and quadratic B-spline, with gradients.
//!
//! Weights are tensor products of 1D functions, evaluated once per particle into a
//! [`Stencil`] of at most 3 nodes per axis.

use crate::base::dim::Dim;
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
    /// Nodes per axis in a stencil.
    pub const fn nodes(self) -> usize {
        match self {
            ShapeKind::Linear => 2,
            ShapeKind::Ugimp | ShapeKind::Bspline => 3,
        }
    }

    /// Offset (cell units) from the particle position to the start of the interval whose
    /// floor is the stencil's first node (`l` is the particle half-width in cell units).
    #[inline(always)]
    pub fn offset(self, l: f64) -> f64 {
        match self {
            ShapeKind::Linear => 0.0,
            ShapeKind::Ugimp => l,
            ShapeKind::Bspline => 0.5,
        }
    }

    /// Whether the stencil of a particle at `xi` (cell units) lies within nodes `0..=cells`.
    #[inline(always)]
    pub fn fits(self, xi: f64, l: f64, cells: usize) -> bool {
        let lo = xi - self.offset(l);
        lo >= 0.0 && lo < (cells + 2 - self.nodes()) as f64
    }

    /// Values per axis the [`StencilCache`] keeps: what [`expand`](Self::expand) rebuilds
    /// the weights and derivatives from, exactly (a quarter to a sixth of storing them).
    pub const fn params(self) -> usize {
        match self {
            ShapeKind::Linear | ShapeKind::Bspline => 1,
            ShapeKind::Ugimp => 4,
        }
    }

    /// The stencil on one axis: its first node and the parameters its weights follow from
    /// (the fraction of a cell for linear and B-spline; the two outer weights and their
    /// derivatives per cell unit for uGIMP). `xi` is the position in cell units from the
    /// grid origin, `l` the half-width in cell units. Callers ensure the stencil
    /// [`fits`](Self::fits), so every floor below is of a non-negative number and
    /// truncation computes it cheaply (through i64, whose conversions to and from f64 are
    /// single instructions on x86-64 where usize's are not).
    #[inline(always)]
    pub fn locate(self, xi: f64, l: f64) -> (usize, [f64; 4]) {
        match self {
            ShapeKind::Linear => {
                let base = xi as i64;
                (base as usize, [xi - base as f64, 0.0, 0.0, 0.0])
            }
            ShapeKind::Ugimp => {
                let base = (xi - l) as i64;
                let r = xi - base as f64;
                let ((s0, g0), (s2, g2)) = (gimp_1d(r, l), gimp_1d(r - 2.0, l));
                (base as usize, [s0, s2, g0, g2])
            }
            ShapeKind::Bspline => {
                let base = (xi - 0.5) as i64;
                (base as usize, [xi - base as f64, 0.0, 0.0, 0.0])
            }
        }
    }

    /// First node, 1D weights and d/dx of the stencil on one axis ([`locate`](Self::locate)
    /// then [`expand`](Self::expand)).
    #[inline(always)]
    pub fn axis(self, xi: f64, l: f64, inv_h: f64) -> (usize, [f64; 3], [f64; 3]) {
        let (base, p) = self.locate(xi, l);
        let (w, dw) = self.expand(&p, inv_h);
        (base, w, dw)
    }

    /// 1D weights and d/dx (`inv_h` the inverse cell size) of the stencil's nodes on one
    /// axis from the parameters of [`locate`](Self::locate).
    #[inline(always)]
    pub fn expand(self, p: &[f64], inv_h: f64) -> ([f64; 3], [f64; 3]) {
        match self {
            ShapeKind::Linear => {
                let f = p[0];
                ([1.0 - f, f, 0.0], [-inv_h, inv_h, 0.0])
            }
            ShapeKind::Ugimp => {
                let (s0, s2, g0, g2) = (p[0], p[1], p[2], p[3]);
                // The middle node by partition of unity (weights sum to 1, derivatives to 0).
                (
                    [s0, 1.0 - s0 - s2, s2],
                    [g0 * inv_h, -(g0 + g2) * inv_h, g2 * inv_h],
                )
            }
            ShapeKind::Bspline => {
                let f = p[0];
                let (a, b, c) = (1.5 - f, f - 1.0, f - 0.5);
                (
                    [0.5 * a * a, 0.75 - b * b, 0.5 * c * c],
                    [-a * inv_h, -2.0 * b * inv_h, c * inv_h],
                )
            }
        }
    }
}

/// uGIMP weight and its derivative (per cell unit) at signed distance `r` (cell units) from
/// a node, particle half-width `l` (Bardenhagen & Kober 2004, Eq. 39 in 1D): the tent
/// function averaged over the particle, S = (H(r + l) - H(r - l)) / (2 l) with H the tent's
/// antiderivative. Written with clamps instead of branches, which mispredict here.
#[inline(always)]
fn gimp_1d(r: f64, l: f64) -> (f64, f64) {
    let anti = |x: f64| {
        let c = x.clamp(-1.0, 1.0);
        0.5 + c - 0.5 * c * c.abs()
    };
    let tent = |x: f64| (1.0 - x.abs()).max(0.0);
    let inv = 0.5 / l;
    (
        (anti(r + l) - anti(r - l)) * inv,
        (tent(r + l) - tent(r - l)) * inv,
    )
}

/// Shape-function values and gradients of one particle on its `N` nodes per axis.
#[derive(Clone, Copy, Debug)]
pub struct Stencil<const N: usize> {
    /// Linear index of the stencil's first node (lowest on every axis).
    pub first: usize,
    /// 1D weights per axis (the unused third axis in 2D has weight 1 on its only node).
    pub w: [[f64; 3]; 3],
    /// 1D derivatives per axis (1/m).
    pub dw: [[f64; 3]; 3],
}

impl<const N: usize> Stencil<N> {
    /// As [`for_each`](Self::for_each), with each node replaced by its entry in `targets`
    /// (a crack-aware particle's grid entries, in the same node order).
    #[inline(always)]
    pub fn for_each_target<D: Dim>(
        &self,
        stride: &[usize; 3],
        targets: &[u32],
        mut f: impl FnMut(usize, f64, D::Vec),
    ) {
        let mut l = 0;
        self.for_each::<D>(stride, |_, w, g| {
            f(targets[l] as usize, w, g);
            l += 1;
        });
    }

    /// Calls `f(node, weight, gradient)` for every node of the stencil, in a fixed order.
    #[inline(always)]
    pub fn for_each<D: Dim>(&self, stride: &[usize; 3], mut f: impl FnMut(usize, f64, D::Vec)) {
        let nk = if D::D == 3 { N } else { 1 };
        for k in 0..nk {
            for j in 0..N {
                let row = self.first_node::<D>(stride, j, k);
                let wjk = self.w[1][j] * self.w[2][k];
                for i in 0..N {
                    f(
                        row + i,
                        self.w[0][i] * wjk,
                        D::grad(&self.w, &self.dw, i, j, k),
                    );
                }
            }
        }
    }

    /// The stencil's rows of `N` nodes along x (see [`Rows`]), y fastest.
    #[inline(always)]
    pub fn rows<D: Dim>(&self, stride: &[usize; 3]) -> Rows {
        let nk = if D::D == 3 { N } else { 1 };
        let mut rows = Rows {
            len: N * nk,
            first: [0; 9],
            q: [0.0; 9],
            gy: [0.0; 9],
            gz: [0.0; 9],
        };
        let mut layer = self.first;
        for k in 0..nk {
            let (w2, dw2) = (self.w[2][k], self.dw[2][k]);
            for j in 0..N {
                let (r, w1) = (k * N + j, self.w[1][j]);
                rows.first[r] = layer + j * stride[1];
                rows.q[r] = w1 * w2;
                (rows.gy[r], rows.gz[r]) = (self.dw[1][j] * w2, w1 * dw2);
            }
            layer += stride[2];
        }
        rows
    }

    /// Index of the first node of the row at offsets `j` (y) and `k` (z) from the stencil's
    /// first node; in 2D the z term is left out at compile time.
    #[inline(always)]
    fn first_node<D: Dim>(&self, stride: &[usize; 3], j: usize, k: usize) -> usize {
        let row = self.first + stride[1] * j;
        if D::D == 3 { row + stride[2] * k } else { row }
    }
}

/// A stencil's rows of nodes along x: node `i` of row `r` is `first[r] + i`, with weight
/// `w[0][i] * q[r]` and gradient `dw[0][i] * q[r] * x̂ + w[0][i] * (0, gy[r], gz[r])`. Hot
/// loops factor their per-row work out of the per-node work this way; the table is built
/// once per particle so those loops index it without dividing a row number into (j, k). Only
/// [`Stencil::rows`] builds one, so the rows' first nodes increase and the last row ends
/// highest (the scatters' single bounds check relies on it).
#[derive(Clone, Copy, Debug)]
pub struct Rows {
    /// Number of rows: `N` in 2D, `N * N` in 3D.
    pub(crate) len: usize,
    /// First node of each row.
    pub(crate) first: [usize; 9],
    /// Weight factor of each row, w_y w_z.
    pub(crate) q: [f64; 9],
    /// y component of each row's gradient factor, dw_y w_z.
    pub(crate) gy: [f64; 9],
    /// z component of each row's gradient factor, w_y dw_z (in 2D dw_z = 0).
    pub(crate) gz: [f64; 9],
}

impl Rows {
    /// One past the last node of the stencil, whose rows of `n` nodes come in increasing
    /// node order.
    #[inline(always)]
    pub fn end(&self, n: usize) -> usize {
        self.first[self.len - 1] + n
    }
}

/// Every particle's stencil, evaluated once after the particles move and read by each
/// system that needs it until they move again (up to four times a step): the linear index
/// of its first node and per axis the shape's [`params`](ShapeKind::params), from which the
/// weights and derivatives are rebuilt on reading. Keeping the parameters instead of the
/// weights, and one node index instead of one per axis, shrinks what the passes over the
/// particles stream from memory.
#[derive(Clone, Debug, Default)]
pub struct StencilCache {
    /// Linear index of each particle's first stencil node.
    pub first: Vec<u32>,
    /// Per particle and axis: the shape's parameters.
    pub params: Vec<f64>,
    /// Inverse cell size per axis (1/m).
    pub inv_h: [f64; 3],
}

impl StencilCache {
    /// Cached parameters per particle for `shape` in `D` dimensions.
    pub const fn per<D: Dim>(shape: ShapeKind) -> usize {
        shape.params() * D::D
    }

    /// Sizes the cache for `n` particles of `shape` on a grid of inverse cell size `inv_h`
    /// and lends its columns for `bin` to fill.
    pub fn resize<D: Dim>(
        &mut self,
        n: usize,
        shape: ShapeKind,
        inv_h: D::Vec,
    ) -> (&mut [u32], &mut [f64]) {
        for a in 0..D::D {
            self.inv_h[a] = inv_h[a];
        }
        self.first.resize(n, 0);
        self.params.resize(n * Self::per::<D>(shape), 0.0);
        (&mut self.first, &mut self.params)
    }
}

impl<const N: usize> Stencil<N> {
    /// The cached stencil of particle `i` for shape `s` (whose nodes per axis are `N`).
    #[inline(always)]
    pub fn cached<D: Dim>(s: ShapeKind, cache: &StencilCache, i: usize) -> Self {
        let per = StencilCache::per::<D>(s);
        Self::from_cache::<D>(
            s,
            cache.first[i],
            &cache.params[i * per..(i + 1) * per],
            &cache.inv_h,
        )
    }

    /// A stencil of shape `s` from one particle's cache entries: its first node and its
    /// [`per`](StencilCache::per) parameters, on a grid of inverse cell size `inv_h`.
    #[inline(always)]
    pub fn from_cache<D: Dim>(s: ShapeKind, first: u32, src: &[f64], inv_h: &[f64; 3]) -> Self {
        debug_assert_eq!(s.nodes(), N);
        let mut st = Stencil {
            first: first as usize,
            w: [[1.0, 0.0, 0.0]; 3],
            dw: [[0.0; 3]; 3],
        };
        let p = s.params();
        for a in 0..D::D {
            (st.w[a], st.dw[a]) = s.expand(&src[p * a..p * (a + 1)], inv_h[a]);
        }
        st
    }
}

/// Evaluates `$body` with the const `$s` bound to the shape function (and `$n` to its nodes
/// per axis), so the compiler specialises per-particle shape code and unrolls stencil
/// loops (no match on the kind inside a particle loop).
#[macro_export]
macro_rules! with_shape {
    ($shape:expr, $s:ident, $n:ident => $body:expr) => {
        $crate::with_shape!($shape, $s => {
            const $n: usize = $s.nodes();
            $body
        })
    };
    ($shape:expr, $s:ident => $body:expr) => {
        match $shape {
            $crate::physics::shape::ShapeKind::Linear => {
                const $s: $crate::physics::shape::ShapeKind = $crate::physics::shape::ShapeKind::Linear;
                $body
            }
            $crate::physics::shape::ShapeKind::Ugimp => {
                const $s: $crate::physics::shape::ShapeKind = $crate::physics::shape::ShapeKind::Ugimp;
                $body
            }
            $crate::physics::shape::ShapeKind::Bspline => {
                const $s: $crate::physics::shape::ShapeKind = $crate::physics::shape::ShapeKind::Bspline;
                $body
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clamped uGIMP form matches the piecewise definition of Bardenhagen & Kober (2004).
    #[test]
    fn gimp_matches_piecewise_form() {
        let l = 0.25;
        for s in 0..400 {
            let r = -1.5 + s as f64 * 0.0075;
            let d = r.abs();
            let (want, dwant) = if d < l {
                (1.0 - (r * r + l * l) / (2.0 * l), -r / l)
            } else if d < 1.0 - l {
                (1.0 - d, -r.signum())
            } else if d < 1.0 + l {
                let e = 1.0 + l - d;
                (e * e / (4.0 * l), -r.signum() * e / (2.0 * l))
            } else {
                (0.0, 0.0)
            };
            let (got, dgot) = gimp_1d(r, l);
            assert!((got - want).abs() < 1e-14, "S at r={r}: {got} vs {want}");
            assert!(
                (dgot - dwant).abs() < 1e-13,
                "dS at r={r}: {dgot} vs {dwant}"
            );
        }
    }

    /// uGIMP on a particle whose domain lies inside one cell is the linear shape: each
    /// node's weight and gradient the linear ones (the hat's value and slope at the centre,
    /// the mean over the domain of a hat that is linear there), nodes beyond the cell zero.
    /// The static solver takes the linear stencil on such scenes on this identity.
    #[test]
    fn ugimp_inside_a_cell_is_linear() {
        let (inv_h, cell) = (500.0, 7.0);
        for l in [0.05, 0.125, 0.25, 0.5] {
            for s in 0..=100 {
                // Domains from touching the cell's lower edge to touching its upper one.
                let xi = cell + l + (1.0 - 2.0 * l) * s as f64 / 100.0;
                let (gb, gw, gd) = ShapeKind::Ugimp.axis(xi, l, inv_h);
                let (lb, lw, ld) = ShapeKind::Linear.axis(xi, l, inv_h);
                let weight = |base: usize, w: &[f64; 3], node: usize| {
                    if node >= base && node < base + 3 {
                        w[node - base]
                    } else {
                        0.0
                    }
                };
                for node in [6, 7, 8, 9] {
                    let (ug, li) = (weight(gb, &gw, node), weight(lb, &lw, node));
                    let (dug, dli) = (weight(gb, &gd, node), weight(lb, &ld, node));
                    assert!(
                        (ug - li).abs() < 1e-12,
                        "l {l} xi {xi} node {node}: {ug} vs {li}"
                    );
                    assert!(
                        (dug - dli).abs() < 1e-9 * inv_h,
                        "l {l} xi {xi} node {node}: {dug} vs {dli}"
                    );
                }
            }
        }
    }

    /// Partition of unity, zero gradient sum and linear completeness hold for every kind.
    #[test]
    fn partition_of_unity_and_linear_reproduction() {
        for shape in [ShapeKind::Linear, ShapeKind::Ugimp, ShapeKind::Bspline] {
            for s in 0..200 {
                let xi = 3.0 + s as f64 * 0.0137;
                let (base, w, dw) = shape.axis(xi, 0.25, 2.0);
                let n = shape.nodes();
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
