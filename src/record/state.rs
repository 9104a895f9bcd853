//! What a run carries from step to step besides the World: the recorded history and the
//! output and checkpoint cadences. Snapshots store it so a resumed run continues exactly.

use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::record::history::{History, Row};
use crate::record::probe::Probe;
use crate::store::world::{Energies, World};

/// Run-loop state that must survive a restart.
#[derive(Clone, Debug, Default)]
pub struct RunState {
    /// Everything recorded so far (probe samples every step, rows at the history cadence).
    pub history: History,
    /// Simulated time of the next history row (s).
    pub next_history: f64,
    /// Simulated time of the next VTK frame (s).
    pub next_frame: f64,
    /// Simulated time of the next time-based checkpoint (s; infinite when there is none).
    pub next_checkpoint: f64,
    /// Times of the VTK frames written so far (s); frame k is `particles_{k:05}.vtu`.
    pub frames: Vec<f64>,
    /// Initial centre of mass, about which angular momentum is measured (m).
    pub centre: [f64; 3],
}

impl RunState {
    /// The state at t = 0 of `world`, with the first cadence marks set.
    pub fn start<D: Dim>(
        world: &World<D>,
        probes: usize,
        steps: u64,
        history_interval: f64,
        frame_interval: f64,
        checkpoint_interval: Option<f64>,
    ) -> Self {
        let centre = centre_of_mass(world);
        RunState {
            history: History {
                probes: vec![Vec::with_capacity((steps as usize + 1).min(1 << 20)); probes],
                ..History::default()
            },
            next_history: history_interval,
            next_frame: frame_interval,
            next_checkpoint: checkpoint_interval.unwrap_or(f64::INFINITY),
            frames: Vec::new(),
            centre: D::to_xyz(centre),
        }
    }

    /// Samples every probe (once per step, including step 0).
    pub fn sample<D: Dim>(&mut self, world: &World<D>, probes: &[Probe]) {
        self.history.time.push(world.time);
        for (k, p) in probes.iter().enumerate() {
            self.history.probes[k].push(p.sample(world));
        }
    }

    /// Appends a history row with energies `e`.
    pub fn record<D: Dim>(&mut self, world: &World<D>, e: Energies) -> &Row {
        let p = &world.particles;
        let mut scale = [ExactSum::new()];
        (0..p.len()).for_each(|i| scale[0].add(p.mass[i] * D::dot(p.v[i], p.v[i]).sqrt()));
        world.domain.sum(&mut scale);
        let scale = scale[0].value();
        let centre = D::from_slice(&self.centre[..D::D]);
        self.history.rows.push(Row {
            step: world.step,
            time: world.time,
            energies: e,
            momentum: D::to_xyz(world.momentum()),
            momentum_scale: scale,
            angular: world.angular_momentum(centre),
        });
        self.history.rows.last().expect("just pushed")
    }
}

/// The centre of mass over every rank, summed exactly (so the same for any split).
fn centre_of_mass<D: Dim>(world: &World<D>) -> D::Vec {
    let p = &world.particles;
    let mut sums: [ExactSum; 4] = Default::default();
    for i in 0..p.len() {
        sums[0].add(p.mass[i]);
        for a in 0..D::D {
            sums[1 + a].add(p.x[i][a] * p.mass[i]);
        }
    }
    world.domain.sum(&mut sums);
    let total = sums[0].value();
    let mut centre = D::zero();
    for a in 0..D::D {
        centre[a] = sums[1 + a].value() / total;
    }
    centre
}
