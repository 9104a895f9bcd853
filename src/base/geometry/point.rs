//! The vector operations the geometric predicates need, shared by 2D and 3D points.

use glam::{DVec2, DVec3};
use std::fmt::Debug;
use std::ops::{Add, Index, IndexMut, Mul, Sub};

/// A point or vector of two or three components (glam's `DVec2` or `DVec3`).
pub trait Point:
    Copy
    + Debug
    + PartialEq
    + Send
    + Sync
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<f64, Output = Self>
    + Index<usize, Output = f64>
    + IndexMut<usize>
{
    /// Number of components.
    const DIM: usize;
    /// Dot product.
    fn dot(self, other: Self) -> f64;
    /// The point padded to three components (z = 0 in 2D).
    fn xyz(self) -> [f64; 3];
}

impl Point for DVec2 {
    const DIM: usize = 2;
    #[inline(always)]
    fn dot(self, other: DVec2) -> f64 {
        DVec2::dot(self, other)
    }
    fn xyz(self) -> [f64; 3] {
        [self.x, self.y, 0.0]
    }
}

impl Point for DVec3 {
    const DIM: usize = 3;
    #[inline(always)]
    fn dot(self, other: DVec3) -> f64 {
        DVec3::dot(self, other)
    }
    fn xyz(self) -> [f64; 3] {
        self.to_array()
    }
}
