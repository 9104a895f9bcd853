//! The particle-node line against crack elements on degenerate geometry: exact predicates
//! and the documented tie rule (a point exactly on the crack counts as above it).

use fissure::dim::{D2, D3, Dim};
use glam::{DVec2, DVec3};

fn v2(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// Crossings of the line p -> q with every segment of the polyline `pts`, per segment.
fn crossings(p: DVec2, q: DVec2, pts: &[DVec2]) -> Vec<i8> {
    (0..pts.len() - 1)
        .map(|k| D2::crossing(p, q, pts, [k as u32, k as u32 + 1]))
        .collect()
}

#[test]
fn proper_crossings_report_the_particle_side() {
    let crack = [v2(0.0, 0.0), v2(1.0, 0.0)];
    // Above is left of the crack's direction (+x), i.e. +y.
    assert_eq!(crossings(v2(0.5, 0.3), v2(0.5, -0.2), &crack), [1]);
    assert_eq!(crossings(v2(0.5, -0.3), v2(0.5, 0.2), &crack), [-1]);
    assert_eq!(crossings(v2(0.5, 0.3), v2(0.5, 0.1), &crack), [0]);
    // Past the end of the crack: no crossing.
    assert_eq!(crossings(v2(1.5, 0.3), v2(1.5, -0.2), &crack), [0]);
}

#[test]
fn a_node_on_the_crack_line_counts_as_above() {
    let crack = [v2(0.0, 0.0), v2(1.0, 0.0)];
    let node = v2(0.5, 0.0);
    assert_eq!(
        crossings(v2(0.4, -0.3), node, &crack),
        [-1],
        "below crosses"
    );
    assert_eq!(crossings(v2(0.4, 0.3), node, &crack), [0], "above does not");
    // Tiny offsets are resolved exactly, not by a tolerance.
    assert_eq!(crossings(v2(0.4, -1e-300), node, &crack), [-1]);
    assert_eq!(crossings(v2(0.4, 1e-300), node, &crack), [0]);
}

#[test]
fn a_line_through_a_shared_vertex_crosses_once() {
    // A kinked crack; the line x = 1 passes exactly through the kink.
    let crack = [v2(0.0, 0.0), v2(1.0, 0.1), v2(2.0, 0.0)];
    let c = crossings(v2(1.0, 1.0), v2(1.0, -1.0), &crack);
    assert_eq!(c.iter().filter(|&&s| s != 0).count(), 1, "{c:?}");
    assert!(c.contains(&1));
    // A line touching the vertex of a V without crossing the polyline: zero or two.
    let vee = [v2(0.0, 1.0), v2(1.0, 0.0), v2(2.0, 1.0)];
    let c = crossings(v2(0.0, 0.0), v2(2.0, 0.0), &vee);
    assert_eq!(c.iter().filter(|&&s| s != 0).count() % 2, 0, "{c:?}");
}

#[test]
fn a_polyline_crossed_twice_counts_as_none() {
    // A U-shaped crack; the line goes in one arm and out the other.
    let u = [v2(0.0, 1.0), v2(0.0, 0.0), v2(1.0, 0.0), v2(1.0, 1.0)];
    let c = crossings(v2(-0.5, 0.5), v2(1.5, 0.5), &u);
    assert_eq!(c.iter().filter(|&&s| s != 0).count(), 2, "{c:?}");
}

#[test]
fn triangle_crossings_in_3d() {
    let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let e = [0, 1, 2];
    // Counterclockwise seen from +z: above is +z.
    let (p, q) = (DVec3::new(0.2, 0.2, 0.5), DVec3::new(0.2, 0.2, -0.5));
    assert_eq!(D3::crossing(p, q, &tri, e), 1);
    assert_eq!(D3::crossing(q, p, &tri, e), -1);
    let outside = DVec3::new(0.8, 0.8, 0.5);
    assert_eq!(D3::crossing(outside, outside - DVec3::Z, &tri, e), 0);
}
