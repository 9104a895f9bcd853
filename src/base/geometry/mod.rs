//! Geometry below every store: points, distances, crack elements and their exact
//! predicates, axis-aligned boxes and closed surfaces. A leaf of the module graph: it imports nothing of
//! the crate, so the dimension, the crack store and the systems can all build on it.

mod bounds;
mod closed_surface;
mod distance;
mod element;
mod outline;
mod point;

pub use bounds::{Aabb, meeting_pairs};
pub use closed_surface::{ClosedSurface, SurfaceDefect, TriangleList};
pub use distance::{point_segment, point_segment_sq, point_triangle, segment_segment};
pub use element::{Element, NUDGE, Segment, Triangle};
pub use outline::Outline;
pub use point::Point;
