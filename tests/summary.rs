//! summary.json reports what a run cost.

mod common;
use common::{mixed_scene, run_text};

/// The peak resident memory is at least the particle store (it is all resident while the
/// run steps) and, on Linux, always reported.
#[test]
fn peak_memory_covers_the_particle_store() {
    let s = run_text(&mixed_scene(3, "ugimp", "usavg")).summary;
    let store = (s.particles * s.bytes_per_particle + s.nodes * s.bytes_per_node) as u64;
    let linux = std::path::Path::new("/proc/self/status").exists();
    match s.peak_resident_bytes {
        Some(peak) => assert!(peak >= store, "peak {peak} B below the stores' {store} B"),
        None => assert!(!linux, "/proc/self/status reports VmHWM"),
    }
}

/// A free block moving rigidly at 100 m/s for 15 us travels 1.5 cells, so with linear shape
/// functions every particle ends in another cell than it started in; at rest none does;
/// with uGIMP the count is not reported.
#[test]
fn cell_crossings_count_the_particles_that_changed_cell() {
    let scene = |shape: &str, speed: f64| {
        format!(
            r#"[simulation]
dimension = 2
shape = "{shape}"
duration = 1.5e-5
[grid]
min = [-0.003, -0.003]
max = [0.01, 0.007]
cell = [0.001, 0.001]
[[material]]
name = "m"
E = 1e9
nu = 0.3
rho = 1000.0
[[body]]
material = "m"
box = {{ min = [0.0, 0.0], max = [0.004, 0.004] }}
velocity = [{speed:e}, 0.0]
"#
        )
    };
    let moving = run_text(&scene("linear", 100.0)).summary;
    assert_eq!(moving.cell_crossings, Some(moving.particles));
    assert_eq!(
        run_text(&scene("linear", 0.0)).summary.cell_crossings,
        Some(0)
    );
    assert_eq!(
        run_text(&scene("ugimp", 100.0)).summary.cell_crossings,
        None
    );
}

/// The edge plate's crack at y = 0 lies half a cell from the node rows, and nothing is
/// reported; with the grid moved half a cell, y = 0 is a node row and summary.json names
/// the crack, the axis and the row.
#[test]
fn a_crack_on_a_node_row_is_reported() {
    let growth = "initiation = \"time\"\nat = 1.0";
    let text = common::edge_plate(growth, 1.0e-7);
    assert!(run_text(&text).summary.node_lines.is_empty());
    let moved = (text.replace("min = [-0.0015, -0.00875]", "min = [-0.0015, -0.009]"))
        .replace("max = [0.0095, 0.00875]", "max = [0.0095, 0.009]");
    let lines = run_text(&moved).summary.node_lines;
    assert_eq!(lines.len(), 1, "{lines:?}");
    let n = &lines[0];
    assert_eq!(
        (n.crack.as_str(), n.axis.as_str(), n.share),
        ("edge", "y", 1.0)
    );
    assert!(n.at.abs() < 1e-12, "{}", n.at);
}

/// A 32 x 8 mm plane-stress strip at rest in 1 mm cells with a centre crack of half-length
/// `half` (m) along y = 6.5 mm, tips at both ends, run for `duration` (s), then `rest`.
fn centre_crack(half: f64, duration: f64, rest: &str) -> String {
    common::strip_2d(
        "plane = \"stress\"",
        duration,
        &format!(
            "[[body]]\nmaterial = \"m\"\nbox = {{ min = [0.004, 0.002], max = [0.036, 0.010] }}\n\
             velocity = [0.0, 0.0]\n[[crack]]\nname = \"c\"\n\
             line = {{ start = [{:.4}, 0.0065], end = [{:.4}, 0.0065], spacing = 5e-4 }}\n\
             tips = [\"start\", \"end\"]\n{rest}",
            0.02 - half,
            0.02 + half
        ),
    )
}

/// A centre crack 0.4 mm long in 1 mm cells lies inside the 3-cell contour of each of its
/// tips, so neither gets J: summary.json names both tips; a 20 mm crack gets J at both
/// and nothing is reported.
#[test]
fn a_crack_inside_its_contour_is_reported() {
    let scene = |half: f64| {
        centre_crack(
            half,
            2e-6,
            "[[load]]\nregion = { min = [0.004, 0.0095], max = [0.036, 0.010] }\n\
             force = [0.0, 1000.0]\n[fracture]\ncontour = 3\n[output]\nhistory_interval = 1e-6\n",
        )
    };
    let tiny = run_text(&scene(2e-4)).summary.contours;
    let tips: Vec<(&str, &str, usize)> = (tiny.iter())
        .map(|c| (c.crack.as_str(), c.tip.as_str(), c.cells))
        .collect();
    assert_eq!(tips, [("c", "start", 3), ("c", "end", 3)]);
    assert!(run_text(&scene(0.01)).summary.contours.is_empty());
}

/// The struck edge of `edge_impact_2d` at 1 mm cells: a region reaching the node row at
/// y = -0.5 mm, whose supports the crack at y = 0 cuts, prescribes some of that row's nodes
/// with a field per side (at most the row's three nodes at x = -2, -1 and 0 mm), and
/// summary.json says so; stopped at y = -1 mm, it drives none; held still instead of
/// moving (as a symmetry plane or a grip is), it is not listed.
#[test]
fn a_boundary_driving_both_sides_of_a_crack_is_reported() {
    let text = std::fs::read_to_string("scenarios/edge_impact_2d.toml").unwrap();
    let text = text.replace("cell = [0.0005, 0.0005]", "cell = [0.001, 0.001]");
    let split = run_text(&text).summary.split_boundaries;
    assert_eq!(split.len(), 1, "{split:?}");
    assert_eq!(split[0].boundary, 0);
    assert!((1..=3).contains(&split[0].nodes), "{split:?}");
    let short = text.replace("max = [0.0, -0.0005] }", "max = [0.0, -0.001] }");
    assert_ne!(short, text);
    assert!(run_text(&short).summary.split_boundaries.is_empty());
    let still = text.replace("velocity = [16.5, 0.0]", "velocity = [0.0, 0.0]");
    assert_ne!(still, text);
    assert!(run_text(&still).summary.split_boundaries.is_empty());
}

/// A centre crack along a row of cell centres (y = 6.5 mm, 1 mm cells, particles at the
/// quarter points, uGIMP) ending at cell centres (x = 16.5 and 23.5 mm): each tip lies on
/// the four diagonals from its cell's particles to the corners across it
/// (`store::crack::tip_lines` derives the count), so summary.json counts 8 lines; ended
/// 0.1 mm further out, none.
#[test]
fn a_tip_on_particle_node_lines_is_reported() {
    let scene = |half: f64| centre_crack(half, 1e-7, "");
    let on = run_text(&scene(0.0035)).summary.tips_on_lines;
    let found: Vec<(&str, usize)> = on.iter().map(|t| (t.crack.as_str(), t.lines)).collect();
    assert_eq!(found, [("c", 8)]);
    assert!(run_text(&scene(0.0036)).summary.tips_on_lines.is_empty());
}
