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
