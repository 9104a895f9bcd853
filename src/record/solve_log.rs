//! What a static scene's solves took: one row per load step (solver.csv, kept in the
//! history and the snapshot) and their totals for summary.json.

use serde::Serialize;

/// How one load step's solve went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Solved {
    /// Conjugate-gradient iterations.
    pub iterations: usize,
    /// Final residual over the external force's norm.
    pub residual: f64,
    /// Rigid motions left free (a body held by no support: up to 3 in 2D, 6 in 3D).
    pub free_motions: usize,
    /// The part of the load's norm along them, removed before the solve.
    pub imbalance: f64,
    /// Crack-face pairs closed at the solution.
    pub closed_faces: usize,
    /// Solves the contact active set took (1 without contact; 0 for a load step that
    /// changed nothing and kept the last answer).
    pub contact_rounds: usize,
    /// Newton iterations (plastic scenes; 0 for a linear step, which solves once).
    pub newton: usize,
    /// Sparse factorizations (the direct solver; 0 under conjugate gradients).
    pub factorizations: usize,
    /// Entries of the last factor (the direct solver's fill).
    pub factor_entries: usize,
    /// Whether "auto" chose the direct solve and went to conjugate gradients instead, its
    /// factor being too large for the memory available.
    pub too_large: bool,
}

impl Solved {
    /// Whether this step kept the last answer (the same loads and supports at both ends,
    /// the cracks as the last solve left them): every solve takes at least one contact
    /// round, such a step none.
    pub fn kept(&self) -> bool {
        self.contact_rounds == 0
    }

    /// The row of a step that kept the answer of the step whose row is `last`: its
    /// residual, rigid motions, imbalance and closed faces, no work.
    pub fn keeping(last: &Solved) -> Solved {
        Solved {
            residual: last.residual,
            free_motions: last.free_motions,
            imbalance: last.imbalance,
            closed_faces: last.closed_faces,
            ..Solved::default()
        }
    }
}

/// What a static scene's load steps took: counts, iterations and the worst residual.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SolveLog {
    /// Load steps solved.
    pub load_steps: u64,
    /// Conjugate-gradient iterations, all load steps.
    pub iterations: u64,
    /// Most iterations in one load step.
    pub most_iterations: u64,
    /// Largest final residual over the external force.
    pub worst_residual: f64,
    /// Rigid motions left free at the last load step.
    pub free_motions: usize,
    /// Largest part of a load step's load removed as imbalance along them.
    pub largest_imbalance: f64,
    /// Crack-face pairs closed at the last load step.
    pub closed_faces: usize,
    /// Most solves one load step's contact active set took.
    pub most_contact_rounds: usize,
    /// Newton iterations, all load steps (plastic scenes).
    pub newton_iterations: u64,
    /// Most Newton iterations in one load step.
    pub most_newton: u64,
    /// Sparse factorizations, all load steps (0: conjugate gradients throughout).
    pub factorizations: u64,
    /// Most entries of one factor (its memory: 8 bytes each).
    pub factor_entries: u64,
    /// Load steps whose direct solve (under "auto") was too large for the memory available
    /// and went to conjugate gradients.
    pub too_large: u64,
    /// The coarse grid's stiffnesses factorized by this invocation (`linear =
    /// "two_level"`): one, and another only when the supports the particles see change (a
    /// grown crack keeps it); a resumed run makes its first afresh.
    pub coarse_factorizations: u64,
}

/// One load step's solve, as solver.csv and the snapshot keep it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveRow {
    /// The load step (its step number).
    pub step: u64,
    /// Its end time (s): the load factor's time.
    pub time: f64,
    /// What its solves took.
    pub solved: Solved,
}

impl SolveRow {
    /// Numbers per row in a snapshot.
    pub const VALUES: usize = 11;

    /// The row's numbers for a snapshot (its step apart), in solver.csv's column order.
    pub fn values(&self) -> [f64; Self::VALUES] {
        let s = &self.solved;
        [
            self.time,
            s.newton as f64,
            s.iterations as f64,
            s.factorizations as f64,
            s.residual,
            s.contact_rounds as f64,
            s.closed_faces as f64,
            s.free_motions as f64,
            s.imbalance,
            s.factor_entries as f64,
            s.too_large as u8 as f64,
        ]
    }

    /// The row of step `step` from a snapshot's `values` (counts are whole numbers well
    /// inside f64's integers).
    pub fn from_values(step: u64, v: &[f64]) -> Self {
        let count = |x: f64| x as usize;
        SolveRow {
            step,
            time: v[0],
            solved: Solved {
                newton: count(v[1]),
                iterations: count(v[2]),
                factorizations: count(v[3]),
                residual: v[4],
                contact_rounds: count(v[5]),
                closed_faces: count(v[6]),
                free_motions: count(v[7]),
                imbalance: v[8],
                factor_entries: count(v[9]),
                too_large: v[10] != 0.0,
            },
        }
    }
}

impl SolveLog {
    /// The totals of the load steps `rows`.
    pub fn from_rows(rows: &[SolveRow]) -> Self {
        let mut log = SolveLog::default();
        rows.iter().for_each(|r| log.add(r.solved));
        log
    }

    /// Counts one load step's solve.
    pub fn add(&mut self, s: Solved) {
        self.load_steps += 1;
        self.iterations += s.iterations as u64;
        self.most_iterations = self.most_iterations.max(s.iterations as u64);
        self.worst_residual = self.worst_residual.max(s.residual);
        self.free_motions = s.free_motions;
        self.largest_imbalance = self.largest_imbalance.max(s.imbalance);
        self.closed_faces = s.closed_faces;
        self.most_contact_rounds = self.most_contact_rounds.max(s.contact_rounds);
        self.newton_iterations += s.newton as u64;
        self.most_newton = self.most_newton.max(s.newton as u64);
        self.factorizations += s.factorizations as u64;
        self.factor_entries = self.factor_entries.max(s.factor_entries as u64);
        self.too_large += s.too_large as u64;
    }
}
