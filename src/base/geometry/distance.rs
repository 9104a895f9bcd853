//! Euclidean distances between points, segments and triangles, for the crack
//! classification's clearances (how far things must move before a crossing can change).

use super::Point;
use glam::DVec3;

/// Distance from `x` to the segment `a`-`b` (m).
pub fn point_segment<P: Point>(x: P, a: P, b: P) -> f64 {
    point_segment_sq(x, a, b).sqrt()
}

/// Squared distance from `x` to the segment `a`-`b` (m^2).
pub fn point_segment_sq<P: Point>(x: P, a: P, b: P) -> f64 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    let t = if len2 > 0.0 {
        ((x - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = x - (a + ab * t);
    d.dot(d)
}

/// Distance from `x` to the triangle `a`, `b`, `c` (m): to its plane when `x` projects
/// inside it, else to the nearest edge.
pub fn point_triangle(x: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    if n2 > 0.0 {
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(p, q)| (q - p).cross(x - p).dot(n) >= 0.0);
        if inside {
            return (x - a).dot(n).abs() / n2.sqrt();
        }
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|&(p, q)| point_segment(x, p, q))
        .fold(f64::INFINITY, f64::min)
}

/// Distance between the segments `p1`-`q1` and `p2`-`q2` in 3D (m): the closest pair of
/// interior points when the segments are not parallel, never more than the distance of an
/// endpoint to the other segment.
pub fn segment_segment(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let ends = point_segment(p1, p2, q2)
        .min(point_segment(q1, p2, q2))
        .min(point_segment(p2, p1, q1))
        .min(point_segment(q2, p1, q1));
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, b, e) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
    let denom = a * e - b * b;
    if denom <= 0.0 {
        return ends;
    }
    // Parameters of the closest points of the two infinite lines; an interior pair is the
    // answer only when both lie inside their segments, else an endpoint is nearest.
    let (c, f) = (d1.dot(r), d2.dot(r));
    let s = (b * f - c * e) / denom;
    let t = (a * f - b * c) / denom;
    if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
        ends.min((p1 + d1 * s - (p2 + d2 * t)).length())
    } else {
        ends
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    #[test]
    fn point_segment_interior_and_ends() {
        let (a, b) = (DVec2::new(0.0, 0.0), DVec2::new(2.0, 0.0));
        assert_eq!(point_segment(DVec2::new(1.0, 3.0), a, b), 3.0);
        assert_eq!(point_segment(DVec2::new(5.0, 4.0), a, b), 5.0);
        assert_eq!(point_segment(DVec2::new(-3.0, 0.0), a, a), 3.0);
    }

    #[test]
    fn point_triangle_face_and_edge() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        assert_eq!(point_triangle(DVec3::new(0.25, 0.25, -2.0), a, b, c), 2.0);
        // Beyond the hypotenuse: nearest point (0.5, 0.5, 0).
        let d = point_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((d - 0.5f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn segment_segment_skew_parallel_and_apart() {
        // Skew lines one apart in z, crossing in projection.
        let d = segment_segment(
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, -1.0, 1.0),
            DVec3::new(0.0, 1.0, 1.0),
        );
        assert_eq!(d, 1.0);
        // Parallel and overlapping, two apart.
        let d = segment_segment(
            DVec3::ZERO,
            DVec3::X * 3.0,
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(5.0, 2.0, 0.0),
        );
        assert_eq!(d, 2.0);
        // Collinear with a gap of one.
        let d = segment_segment(DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::X * 4.0);
        assert_eq!(d, 1.0);
    }
}
