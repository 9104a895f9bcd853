//! Spatial dimension: one code path for 2D and 3D.
//!
//! Systems are generic over [`Dim`]; the two instances [`D2`] and [`D3`] supply the vector and
//! matrix types (glam `DVec2`/`DMat2`, `DVec3`/`DMat3`) and the few operations that differ.
//! Grid indices are always `[usize; 3]` with a unit third axis in 2D, so stencil loops are
//! written once.

use crate::crack::{Element, Segment, Triangle};
use crate::error::Unstable;
use crate::fracture::FracturePlan;
use crate::geometry::{point_segment, point_segment_sq, point_triangle, segment_segment};
use crate::snapshot::Columnar;
use crate::sym::{Sym2, Sym3, SymTensor};
use crate::world::World;
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
    type Elem: Element;
    /// The fracture system of this dimension (J and K at crack tips in 2D, at every front
    /// vertex in 3D, stored in the crack scratch).
    const FRACTURE: FractureSystem<Self>;
    /// The growth system of this dimension (tips in 2D, fronts in 3D).
    const GROWTH: GrowthSystem<Self>;

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
    /// Whether the line from `p` to `q` crosses crack element `e` of vertices `v` (2D: the
    /// segment `e[0]`-`e[1]`; 3D: the triangle `e[0]`, `e[1]`, `e[2]`): +1 if `p` is above it (left of
    /// the segment's direction; on the side of the triangle's counterclockwise normal), -1
    /// if below, 0 if there is no crossing. Exact orientation predicates (Shewchuk's, from
    /// `robust`); a point exactly on the crack line or plane counts as above, so a line
    /// through a vertex shared by two segments crosses exactly one of them.
    fn crossing(p: Self::Vec, q: Self::Vec, v: &[Self::Vec], e: Self::Elem) -> i8 {
        Self::crossing_from(p, Self::elem_side(p, v, e), q, v, e)
    }
    /// [`Dim::crossing`] given `sp`, the [`Dim::elem_side`] of `p` (a particle tested against
    /// every node of its stencil computes it once).
    fn crossing_from(p: Self::Vec, sp: i8, q: Self::Vec, v: &[Self::Vec], e: Self::Elem) -> i8;
    /// Side of the line (2D) or plane (3D) of crack element `e` that `x` lies on: +1 above
    /// or on it, -1 below; the first test of [`Dim::crossing`].
    fn elem_side(x: Self::Vec, v: &[Self::Vec], e: Self::Elem) -> i8;
    /// Whether a line through a feature shared by two elements crosses exactly one of them
    /// under [`Dim::crossing`]'s tie rule (2D vertices: the orientation tie rule; 3D edges:
    /// the perturbation of `edge_side`), so that `classify` may treat the feature as
    /// interior.
    const SHARED_FEATURE_SAFE: bool;
    /// Squared distance from `x` to crack element `e` (m^2).
    fn elem_distance_sq(x: Self::Vec, v: &[Self::Vec], e: Self::Elem) -> f64;
    /// Distance from `x` to crack element `e` (m).
    fn elem_distance(x: Self::Vec, v: &[Self::Vec], e: Self::Elem) -> f64 {
        Self::elem_distance_sq(x, v, e).sqrt()
    }
    /// Distance from `x` to the line (2D) or plane (3D) of crack element `e` (m).
    fn plane_distance(x: Self::Vec, v: &[Self::Vec], e: Self::Elem) -> f64;
    /// Unit normal of crack element `e`, pointing above it (left of a segment's direction;
    /// along a counterclockwise triangle's normal).
    fn elem_normal(v: &[Self::Vec], e: Self::Elem) -> Self::Vec;
    /// Distance from feature `k` of crack element `e` to the segment `p`-`q` (m).
    fn feature_distance(
        p: Self::Vec,
        q: Self::Vec,
        v: &[Self::Vec],
        e: Self::Elem,
        k: usize,
    ) -> f64;
}

/// A fracture system: measures at every crack front of the world as the plan says.
pub type FractureSystem<D> = fn(&mut World<D>, &FracturePlan);

/// A growth system: `run` advances the growing crack tips after a step; `needs_k` says
/// whether it reads K at the end of a given step (which must then keep its stencils).
pub struct GrowthSystem<D: Dim> {
    /// Advances the tips.
    pub run: fn(&mut World<D>, Option<&FracturePlan>) -> Result<(), Unstable>,
    /// Whether the tips read K or J at the end of this step.
    pub needs_k: fn(&World<D>, u64) -> bool,
}

/// +1 for a non-negative orientation, -1 otherwise (the tie rule of [`Dim::crossing`]).
#[inline(always)]
fn side(o: f64) -> i8 {
    if o >= 0.0 { 1 } else { -1 }
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
    const SHARED_FEATURE_SAFE: bool = true;
    type Vec = DVec2;
    type Mat = DMat2;
    type Sym = Sym2;
    type Elem = Segment;
    const FRACTURE: FractureSystem<Self> = crate::systems::fracture::run;
    const GROWTH: GrowthSystem<Self> = GrowthSystem {
        run: crate::systems::grow::run,
        needs_k: crate::systems::grow::needs_k,
    };

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
    fn elem_side(x: DVec2, v: &[DVec2], e: Segment) -> i8 {
        let c = |u: DVec2| robust::Coord { x: u.x, y: u.y };
        side(robust::orient2d(
            c(v[e[0] as usize]),
            c(v[e[1] as usize]),
            c(x),
        ))
    }
    fn elem_distance_sq(x: DVec2, v: &[DVec2], e: Segment) -> f64 {
        point_segment_sq::<Self>(x, v[e[0] as usize], v[e[1] as usize])
    }
    fn plane_distance(x: DVec2, v: &[DVec2], e: Segment) -> f64 {
        let (a, b) = (v[e[0] as usize], v[e[1] as usize]);
        let t = b - a;
        let len = t.length();
        if len > 0.0 {
            t.perp_dot(x - a).abs() / len
        } else {
            (x - a).length()
        }
    }
    fn elem_normal(v: &[DVec2], e: Segment) -> DVec2 {
        let ab = v[e[1] as usize] - v[e[0] as usize];
        let len = Self::dot(ab, ab).sqrt();
        DVec2::new(-ab[1] / len, ab[0] / len)
    }
    fn feature_distance(p: DVec2, q: DVec2, v: &[DVec2], e: Segment, k: usize) -> f64 {
        point_segment::<Self>(v[e[k] as usize], p, q)
    }
    fn crossing_from(p: DVec2, sp: i8, q: DVec2, v: &[DVec2], e: Segment) -> i8 {
        let c = |u: DVec2| robust::Coord { x: u.x, y: u.y };
        let (a, b) = (v[e[0] as usize], v[e[1] as usize]);
        if sp == Self::elem_side(q, v, e) {
            return 0;
        }
        let sa = side(robust::orient2d(c(p), c(q), c(a)));
        if sa == side(robust::orient2d(c(p), c(q), c(b))) {
            return 0;
        }
        sp
    }
}

impl Dim for D3 {
    const D: usize = 3;
    const COLOURS: usize = 8;
    const SHARED_FEATURE_SAFE: bool = true;
    type Vec = DVec3;
    type Mat = DMat3;
    type Sym = Sym3;
    type Elem = Triangle;
    const FRACTURE: FractureSystem<Self> = crate::systems::fracture_front::run;
    const GROWTH: GrowthSystem<Self> = GrowthSystem {
        run: crate::systems::grow_front::run,
        needs_k: crate::systems::grow::needs_k,
    };

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
    fn elem_side(x: DVec3, v: &[DVec3], e: Triangle) -> i8 {
        let c = |u: DVec3| robust::Coord3D {
            x: u.x,
            y: u.y,
            z: u.z,
        };
        let [a, b, t] = e.map(|k| c(v[k as usize]));
        // robust::orient3d is positive below the plane of a counterclockwise triangle.
        side(-robust::orient3d(a, b, t, c(x)))
    }
    fn elem_distance_sq(x: DVec3, v: &[DVec3], e: Triangle) -> f64 {
        Self::elem_distance(x, v, e).powi(2)
    }
    fn elem_distance(x: DVec3, v: &[DVec3], e: Triangle) -> f64 {
        let [a, b, c] = e.map(|k| v[k as usize]);
        point_triangle(x, a, b, c)
    }
    fn plane_distance(x: DVec3, v: &[DVec3], e: Triangle) -> f64 {
        let [a, b, c] = e.map(|k| v[k as usize]);
        let n = (b - a).cross(c - a);
        let len = n.length();
        if len > 0.0 {
            n.dot(x - a).abs() / len
        } else {
            point_triangle(x, a, b, c)
        }
    }
    fn elem_normal(v: &[DVec3], e: Triangle) -> DVec3 {
        let [a, b, c] = e.map(|k| v[k as usize]);
        (b - a).cross(c - a).normalize()
    }
    fn feature_distance(p: DVec3, q: DVec3, v: &[DVec3], e: Triangle, k: usize) -> f64 {
        let [a, b] = e.feature(k).map(|i| v[i as usize]);
        segment_segment(p, q, a, b)
    }
    fn crossing_from(p: DVec3, sp: i8, q: DVec3, v: &[DVec3], e: Triangle) -> i8 {
        if sp == Self::elem_side(q, v, e) {
            return 0;
        }
        let [va, vb, vt] = e.map(|k| v[k as usize]);
        let s1 = edge_side(p, q, va, vb);
        let s2 = edge_side(p, q, vb, vt);
        let s3 = edge_side(p, q, vt, va);
        if s1 == s2 && s2 == s3 { sp } else { 0 }
    }
}

/// Directions along which `edge_side` moves a line that meets an edge exactly.
pub const NUDGE: [DVec3; 2] = [
    DVec3::new(0.571_428_57, 0.301_953_12, 0.763_143_73),
    DVec3::new(-0.212_121_21, 0.927_835_05, 0.306_651_63),
];

/// Which side of the line from `p` to `q` the directed edge `a` -> `b` passes (the sign of
/// robust::orient3d(p, q, a, b), as +1 or -1). Where the line meets the edge exactly the
/// line is taken as moved a vanishing distance along a fixed direction (simulation of
/// simplicity): the sign is that of the first-order change, d . ((q - p) x (a - b)), which
/// flips exactly with the edge's direction. So a line through an edge shared by two
/// triangles (met in opposite directions) crosses exactly one of them, and a line through
/// a vertex crosses the one triangle of its fan the moved line passes through.
fn edge_side(p: DVec3, q: DVec3, a: DVec3, b: DVec3) -> i8 {
    let c = |u: DVec3| robust::Coord3D {
        x: u.x,
        y: u.y,
        z: u.z,
    };
    let o = robust::orient3d(c(p), c(q), c(a), c(b));
    if o != 0.0 {
        return side(o);
    }
    let axis = (q - p).cross(a - b);
    NUDGE
        .iter()
        .map(|d| d.dot(axis))
        .find(|&k| k != 0.0)
        .map_or(1, side)
}
