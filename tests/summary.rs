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
