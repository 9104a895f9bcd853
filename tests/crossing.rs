//! The particle-node line against crack elements on degenerate geometry: exact predicates
//! and the documented tie rule (a point exactly on the crack counts as above it).

use fissure::base::geometry::{Element, Segment, Triangle};
use glam::{DVec2, DVec3};

fn v2(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// Crossings of the line p -> q with every segment of the polyline `pts`, per segment.
fn crossings(p: DVec2, q: DVec2, pts: &[DVec2]) -> Vec<i8> {
    (0..pts.len() - 1)
        .map(|k| Segment::from_vertices(&[k as u32, k as u32 + 1]).crossing(p, q, pts))
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
    let e: Triangle = [0, 1, 2];
    // Counterclockwise seen from +z: above is +z.
    let (p, q) = (DVec3::new(0.2, 0.2, 0.5), DVec3::new(0.2, 0.2, -0.5));
    assert_eq!(e.crossing(p, q, &tri), 1);
    assert_eq!(e.crossing(q, p, &tri), -1);
    let outside = DVec3::new(0.8, 0.8, 0.5);
    assert_eq!(e.crossing(outside, outside - DVec3::Z, &tri), 0);
}

/// Crossings of the line `p`-`q` with each triangle of `tris`.
fn tri_crossings(p: DVec3, q: DVec3, v: &[DVec3], tris: &[[u32; 3]]) -> Vec<i8> {
    tris.iter().map(|&t| t.crossing(p, q, v)).collect()
}

/// A hexagonal fan of six counterclockwise triangles around the origin in the plane z = 0.
fn fan() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut v = vec![DVec3::ZERO];
    v.extend((0..6).map(|k| {
        let a = k as f64 * std::f64::consts::PI / 3.0;
        DVec3::new(a.cos(), a.sin(), 0.0)
    }));
    let tris = (0..6u32).map(|k| [0, 1 + k, 1 + (k + 1) % 6]).collect();
    (v, tris)
}

/// A line through an edge shared by two triangles, or through the vertex of a fan, crosses
/// exactly one triangle, the one the line moved a little along the tie-break direction
/// crosses; so does a line ending on an edge (a node on the crack surface).
#[test]
fn lines_through_shared_edges_and_vertices_cross_once() {
    let (v, tris) = fan();
    let edge_point = v[2] * 0.5; // on the edge from the centre to vertex 2
    let cases = [
        (
            edge_point + DVec3::Z,
            edge_point - DVec3::Z,
            "through a shared edge",
        ),
        (
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.0, 0.0, -1.0),
            "through the centre vertex",
        ),
        (
            DVec3::new(0.1, -0.3, 1.0),
            DVec3::new(-0.1, 0.3, -1.0),
            "slanted, through the centre",
        ),
        (
            edge_point - DVec3::new(0.05, 0.02, 1.0),
            edge_point,
            "ending on a shared edge",
        ),
    ];
    for (p, q, what) in cases {
        let c = tri_crossings(p, q, &v, &tris);
        assert_eq!(c.iter().filter(|&&s| s != 0).count(), 1, "{what}: {c:?}");
        // The same as the line moved a small distance along the tie-break direction.
        let d = fissure::base::geometry::NUDGE[0] * 1e-9;
        let moved = tri_crossings(p + d, q + d, &v, &tris);
        if q.z != 0.0 {
            assert_eq!(c, moved, "{what}");
        }
        // Run backwards, the line crosses the same triangle from the other side.
        if q.z != 0.0 {
            let back = tri_crossings(q, p, &v, &tris);
            let flipped: Vec<i8> = c.iter().map(|s| -s).collect();
            assert_eq!(back, flipped, "{what}");
        }
    }
    // A line through a vertex on the fan's rim, shared by two triangles only.
    let rim = v[3];
    let c = tri_crossings(rim + DVec3::Z, rim - DVec3::Z, &v, &tris);
    assert!(c.iter().filter(|&&s| s != 0).count() <= 1, "{c:?}");
}
