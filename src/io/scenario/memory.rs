//! What a scene will hold in memory, estimated before anything is allocated, against what
//! the machine has free: a scene too large for it is refused with the estimate, instead of
//! the process being killed part way through building it.

use super::source::Source;
use crate::base::error::ScenarioError;

/// Bytes a particle costs in all (its store, shape-function stencils, tile lists and the
/// systems' scratch), 2D and 3D; measured on the shipped scenes as resident memory over
/// particle count, rounded up.
const PER_PARTICLE: [f64; 2] = [250.0, 500.0];

/// Bytes a grid node costs in all (the node store and the crack fields' rows), 2D and 3D.
const PER_NODE: [f64; 2] = [150.0, 210.0];

/// Refuses a scene of about `particles` particles and `nodes` nodes in `dim` dimensions
/// that needs more memory than `free` bytes (None: not known, nothing is refused). Split
/// across `ranks`, each rank holds its share of the particles and the whole grid, and
/// `free` is the least any rank's machine has.
pub(super) fn check(
    src: &Source,
    dim: usize,
    (particles, ranks): (f64, usize),
    nodes: f64,
    free: Option<f64>,
) -> Result<(), ScenarioError> {
    let Some(free) = free else {
        return Ok(());
    };
    let k = if dim == 2 { 0 } else { 1 };
    let share = particles / ranks as f64;
    let need = share * PER_PARTICLE[k] + nodes * PER_NODE[k];
    if need <= free {
        return Ok(());
    }
    let gb = |b: f64| b / 1e9;
    let who = match ranks {
        1 => "the scene needs".to_string(),
        n => format!("each of the {n} ranks needs"),
    };
    Err(src.error(
        "grid.cell",
        format!(
            "{who} about {:.1} GB ({share:.3e} particles at about {} bytes and {nodes:.3e} \
             nodes at about {} bytes), more than the {:.1} GB this machine has free: use \
             larger cells or smaller bodies{}",
            gb(need),
            PER_PARTICLE[k],
            PER_NODE[k],
            gb(free),
            if ranks > 1 {
                ", or more ranks on more machines"
            } else {
                ""
            }
        ),
    ))
}

/// Memory the machine has free for a new process (bytes): MemAvailable of /proc/meminfo
/// on Linux; None elsewhere or when it cannot be read.
pub(super) fn available() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3D scene of 1e8 particles and 1e7 nodes needs 52.1 GB: refused with 24 GB free,
    /// accepted with 64 GB or when the free memory is not known.
    #[test]
    fn refuses_only_what_does_not_fit() {
        let text = "[simulation]\ndimension = 3\nduration = 1.0\n[grid]\nmin = [0.0, 0.0, 0.0]\n\
                    max = [1.0, 1.0, 1.0]\ncell = [0.1, 0.1, 0.1]\n";
        let src = Source::parse("m.toml", text, &[]).unwrap();
        let err = check(&src, 3, (1e8, 1), 1e7, Some(24e9))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("about 52.1 GB") && err.contains("24.0 GB"),
            "{err}"
        );
        assert!(check(&src, 3, (1e8, 1), 1e7, Some(64e9)).is_ok());
        assert!(check(&src, 3, (1e8, 1), 1e7, None).is_ok());
    }

    /// Split across 4 ranks, each needs a quarter of the particles' 50 GB and the whole
    /// grid's 2.1 GB: 14.6 GB, accepted with 24 GB free, refused with 8 GB, naming the ranks.
    #[test]
    fn a_split_scene_needs_its_share_per_rank() {
        let text = "[simulation]\ndimension = 3\nduration = 1.0\n[grid]\nmin = [0.0, 0.0, 0.0]\n\
                    max = [1.0, 1.0, 1.0]\ncell = [0.1, 0.1, 0.1]\n";
        let src = Source::parse("m.toml", text, &[]).unwrap();
        assert!(check(&src, 3, (1e8, 4), 1e7, Some(24e9)).is_ok());
        let err = check(&src, 3, (1e8, 4), 1e7, Some(8e9))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("each of the 4 ranks needs about 14.6 GB"),
            "{err}"
        );
    }
}
