//! summary.json: what ran, how fast, how much memory, and every expect's result.

use crate::record::expect::ExpectResult;
use crate::record::probe::ProbeQty;
use crate::record::solve_log::SolveLog;
use crate::store::world::Energies;
use serde::Serialize;
use std::collections::BTreeMap;

/// How a run ended (summary.json's `status`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Reached its end time.
    Completed,
    /// Stopped on request (a signal, or a pause after a set step).
    Interrupted,
    /// Went unstable (a NaN, a particle leaving the grid, a crack growing out of it).
    Unstable,
    /// An output file could not be written.
    Failed,
}

impl Status {
    /// The name summary.json and sweep.csv give it.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Completed => "completed",
            Status::Interrupted => "interrupted",
            Status::Unstable => "unstable",
            Status::Failed => "failed",
        }
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How a run split across MPI ranks was divided and what the ranks sent each other
/// (per rank and per step, averaged over the steps run).
#[derive(Clone, Debug, Serialize)]
pub struct RanksReport {
    /// Number of ranks.
    pub ranks: usize,
    /// Fewest and most particles a rank held at the end.
    pub particles: [usize; 2],
    /// Point-to-point messages a rank sent per step: mean and most over the ranks.
    pub messages_per_step: [f64; 2],
    /// Bytes in them (node values at shared nodes, migrating particles): mean and most.
    pub bytes_per_step: [f64; 2],
    /// Collective operations (exact sums, gathers) per step.
    pub collectives_per_step: f64,
    /// Wall seconds a rank spent inside MPI calls over the run (sending, receiving, and
    /// waiting for peers that had more to do): mean and most over the ranks.
    pub mpi_seconds: [f64; 2],
    /// Times the tiles were divided anew as the particles moved.
    pub rebalances: u32,
    /// Peak resident memory of a rank's process (bytes; Linux `VmHWM`, 0 where the system
    /// does not report it): mean and most over the ranks.
    pub peak_resident_bytes: [u64; 2],
}

/// The run summary written to summary.json at the end of a run.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// 2 or 3.
    pub dimension: usize,
    /// How the run ended.
    pub status: Status,
    /// Why the run stopped early, if it did.
    pub message: Option<String>,
    /// Particle count.
    pub particles: usize,
    /// Grid node count.
    pub nodes: usize,
    /// Steps taken since the start of the run (before a resume too).
    pub steps: u64,
    /// Steps taken by this invocation (fewer than `steps` after a resume).
    pub steps_run: u64,
    /// Simulated time reached (s).
    pub time: f64,
    /// Time step (s).
    pub dt: f64,
    /// Stability limit h_min / c_max (s).
    pub dt_limit: f64,
    /// Wall-clock seconds in the time-step loop.
    pub wall_seconds: f64,
    /// Particles times steps per wall second.
    pub particle_steps_per_second: f64,
    /// Worker threads.
    pub threads: usize,
    /// System names in execution order.
    pub schedule: Vec<String>,
    /// Wall seconds per system.
    pub system_seconds: BTreeMap<String, f64>,
    /// Bytes per particle held by the particle store.
    pub bytes_per_particle: usize,
    /// Bytes per node held by the grid store.
    pub bytes_per_node: usize,
    /// The process's peak resident memory so far (bytes; Linux `VmHWM`), None where the
    /// system does not report it.
    pub peak_resident_bytes: Option<u64>,
    /// With linear shape functions, the particles that ended in another cell than they
    /// started in (each crossing jumps their internal force); None with the other shapes.
    pub cell_crossings: Option<usize>,
    /// Cracks that lay on a line (2D) or plane (3D) of grid nodes when the run began.
    pub node_lines: Vec<NodeLineReport>,
    /// Cracks that passed through particle centres when the run began.
    pub particles_on_cracks: Vec<ParticlesOnReport>,
    /// Cracks whose tips (2D) or front edges (3D) lay on a line from a particle to a node
    /// of its stencil when the run began.
    pub tips_on_lines: Vec<TipLinesReport>,
    /// Moving velocity boundaries with nodes whose support a crack cut at the last step:
    /// they drive the material on both sides of the crack there.
    pub split_boundaries: Vec<SplitBoundaryReport>,
    /// Energies at the end (J).
    pub energies: Energies,
    /// A static scene's solves (None in an explicit run).
    pub static_solve: Option<SolveLog>,
    /// A run split across MPI ranks: the split and the ranks' traffic (None on one rank).
    pub ranks: Option<RanksReport>,
    /// The keys a static scene ignores (explicit runs only: cfl, dt, damping, initial
    /// velocities), as given.
    pub ignored_keys: Vec<String>,
    /// Every probe's last sample (e.g. the crack-mouth opening of an `opening` probe).
    pub probes: Vec<ProbeReport>,
    /// Results of the scenario's `[[expect]]` blocks (only for a completed run).
    pub expects: Vec<ExpectResult>,
    /// Path dependence of J per crack tip and compared contour (`[fracture] compare`).
    pub paths: Vec<PathReport>,
    /// Along 3D fronts: where the tube around a vertex was shrunk to stay inside the body
    /// and the vertex's material, or none fitted (last measurement).
    pub tubes: Vec<TubeReport>,
    /// 2D tips where the last measurement found no J: the contour does not cross the crack.
    pub contours: Vec<ContourReport>,
    /// Every growing crack tip: how far it grew and whether it stopped for good.
    pub growth: Vec<GrowthReport>,
    /// Snapshot this run continued from.
    pub resumed_from: Option<String>,
    /// Newest snapshot written (or resumed from).
    pub snapshot: Option<String>,
    /// Wall seconds spent writing snapshots.
    pub snapshot_seconds: f64,
    /// Bytes of snapshot columns written.
    pub snapshot_bytes: u64,
}

/// How far J on one compared contour is from J on the main contour at a crack tip, over the
/// window from `from` on: max |J_n - J_main| / max |J_main|, with and without the area term.
#[derive(Clone, Debug, Serialize)]
pub struct PathReport {
    /// Crack name.
    pub crack: String,
    /// "start" or "end"; along a 3D front, the worst of its vertices.
    pub tip: String,
    /// Main contour size (cells; in 3D the tube's radius).
    pub main: u32,
    /// Compared contour size (cells; in 3D the tube's radius).
    pub contour: u32,
    /// Start of the window (s).
    pub from: f64,
    /// Relative difference with the area term (Eq. 8; in 3D the volume term of Eq. 33).
    pub with_area: Option<f64>,
    /// Relative difference without it.
    pub without_area: Option<f64>,
}

/// The front vertices of one crack whose tube, at the last measurement, was shrunk to stay
/// inside the body and the vertex's material, or did not fit at all (J and K NaN there).
#[derive(Clone, Debug, Serialize)]
pub struct TubeReport {
    /// Crack name.
    pub crack: String,
    /// Radius asked for (m), `[fracture] domain` cells.
    pub radius: f64,
    /// Front vertices of the crack.
    pub vertices: usize,
    /// Vertices measured on a smaller tube, as ranges ("0-2, 7").
    pub shrunk: String,
    /// Vertices where no tube of 2 cells or more fits.
    pub unfitted: String,
}

/// A 2D crack tip whose J contour, at the last measurement, did not cross the crack once
/// (J and K NaN there): the crack is shorter than the contour, or the tip lies within the
/// contour's size of the grid's edge.
#[derive(Clone, Debug, Serialize)]
pub struct ContourReport {
    /// Crack name.
    pub crack: String,
    /// "start" or "end".
    pub tip: String,
    /// Contour size asked for (cells), `[fracture] contour`.
    pub cells: usize,
}

/// A crack passing through particle centres, whose side of it round-off decides.
#[derive(Clone, Debug, Serialize)]
pub struct ParticlesOnReport {
    /// Crack name.
    pub crack: String,
    /// How many particle centres lie on it (within 1e-7 of a cell).
    pub particles: usize,
}

/// A crack whose tip or front lies on particle-node lines, whose crossing of the crack
/// round-off decides.
#[derive(Clone, Debug, Serialize)]
pub struct TipLinesReport {
    /// Crack name.
    pub crack: String,
    /// How many particle-node lines pass through its tips or front edges (within 1e-7 of
    /// a cell).
    pub lines: usize,
}

/// A velocity boundary prescribing nodes with a velocity field per crack side: it drives
/// every field of its nodes, so the material on both sides of the crack there.
#[derive(Clone, Debug, Serialize)]
pub struct SplitBoundaryReport {
    /// Index of the `[[boundary]]` table.
    pub boundary: usize,
    /// Its nodes that carried more than one velocity field at the last step.
    pub nodes: usize,
}

/// A crack lying on a line or plane of grid nodes, which costs J and K accuracy.
#[derive(Clone, Debug, Serialize)]
pub struct NodeLineReport {
    /// Crack name.
    pub crack: String,
    /// "x", "y" or "z": the axis the line or plane is normal to.
    pub axis: String,
    /// Its coordinate on that axis (m).
    pub at: f64,
    /// The share of the crack's elements on it.
    pub share: f64,
}

/// A probe's last sample.
#[derive(Clone, Debug, Serialize)]
pub struct ProbeReport {
    /// Probe name.
    pub name: String,
    /// What it averages, as in the scenario.
    pub quantity: ProbeQty,
    /// Its last sample (SI units of the quantity); None before any.
    pub last: Option<f64>,
}

/// A growing crack tip at the end of the run.
#[derive(Clone, Debug, Serialize)]
pub struct GrowthReport {
    /// Crack name.
    pub crack: String,
    /// "start" or "end"; "front" for a 3D front.
    pub tip: String,
    /// Where the tip is (m); for a 3D front the mean of its vertices (x, y).
    pub x: [f64; 2],
    /// Length grown (m); for a 3D front its mean advance.
    pub grown: f64,
    /// Time it started to grow (s); null if it did not.
    pub started: Option<f64>,
    /// Fatigue: load cycles to the last check; null without a fatigue law.
    pub cycles: Option<f64>,
    /// Why it stopped growing for good, if it did.
    pub stopped: Option<String>,
}

/// The process's peak resident set size (bytes), from `VmHWM` in /proc/self/status; None
/// where that file does not exist (not Linux) or lacks the line.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
