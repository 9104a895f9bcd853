//! The World: every store, the materials, the scene settings, time and step. Nothing global.

use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::base::sym::SymTensor;
use crate::physics::loads::{Load, VelocityBc};
use crate::physics::material::{Material, Plane};
use crate::physics::shape::{ShapeKind, StencilCache};
use crate::ranks::domain::Domain;
use crate::store::crack::Cracks;
use crate::store::grid::Grid;
use crate::store::particles::Particles;
use crate::store::tiles::Tiles;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// When the stress is updated within a step (Bardenhagen 2002; Nairn 2003).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Update {
    /// Update stress first, from the extrapolated momenta, before internal forces.
    Usf,
    /// Update stress last, from the updated grid velocities.
    Usl,
    /// Half the increment at each of those two points.
    #[default]
    Usavg,
}

/// How a scene is advanced: explicit dynamics, or static equilibrium load step by load step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// Explicit time integration (waves, damping, inertia).
    #[default]
    Explicit,
    /// Equilibrium at each load step, no inertia (`systems::static_solve`).
    Static,
}

/// Which volumetric strain a particle's stress sees (`[simulation] dilatation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Dilatation {
    /// Its own.
    #[default]
    Particle,
    /// The volume-weighted mean over the particles of its cell, material and crack side
    /// (`systems::dilatation`): relieves the volumetric locking of
    /// isochoric plastic flow in plane strain and 3D.
    CellMean,
}

/// How a static scene's linear systems are solved (`[simulation] linear`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum LinearSolver {
    /// The sparse direct factorization in 2D (when its factor fits in memory; conjugate
    /// gradients with the coarse grid for Newton iterations on 10^4 particles or more, all
    /// materials' nu at most 0.35, where a factorization per iteration costs more),
    /// conjugate gradients with the coarse grid in 3D, where a grid's factor fills in far
    /// faster (nested dissection: n^(4/3) entries and n^2 operations against n log n and
    /// n^(3/2) in 2D) and conjugate gradients won at every size measured
    /// (docs/static-solver.md); conjugate gradients with Jacobi on several MPI ranks.
    #[default]
    Auto,
    /// Sparse Cholesky factorization of the assembled K.
    Direct,
    /// Matrix-free conjugate gradients with a Jacobi preconditioner.
    Cg,
    /// Matrix-free conjugate gradients with Jacobi and a coarse grid of four times the
    /// cell size, eight or more on large 3D bodies (a two-level additive Schwarz
    /// preconditioner).
    #[serde(rename = "two_level")]
    TwoLevel,
}

/// The default residual, relative to the external force, at which a static load step has
/// converged (`[simulation] tolerance`): four orders below the discretisation's own error
/// (1e-4 at best in the shipped scenes), and above the floor the iteration's round-off
/// reaches (1e-10 to 3e-9 on the cracked 2D scenes).
pub const STATIC_TOLERANCE: f64 = 1e-8;

/// Scene-wide settings that systems read.
#[derive(Clone, Debug)]
pub struct Settings<D: Dim> {
    /// Explicit dynamics or static load steps.
    pub solver: Solver,
    /// A static scene's convergence tolerance: the residual relative to the external force
    /// at which a load step has converged.
    pub tolerance: f64,
    /// A static scene's linear solver.
    pub linear: LinearSolver,
    /// Shape function.
    pub shape: ShapeKind,
    /// Each particle's own volumetric strain, or its cell's mean.
    pub dilatation: Dilatation,
    /// Stress-update order.
    pub update: Update,
    /// Out-of-plane treatment (None in 3D).
    pub plane: Plane,
    /// Mass-proportional damping alpha = d_k / rho (1/s), Guo & Nairn 2D (2004) Eq. 5.
    pub damping: f64,
    /// Body force per unit mass (m/s^2).
    pub gravity: D::Vec,
    /// Time step (s); a static scene's load step.
    pub dt: f64,
    /// Nodes lighter than this carry no velocity (kg).
    pub mass_tol: f64,
    /// Nodes lighter than this do not move cracks (kg): a thousandth of the lightest
    /// particle. A node at the edge of a particle's support gets a sliver of mass and, with
    /// the internal force on it, a meaningless velocity.
    pub sliver_mass: f64,
    /// Out-of-plane thickness (m) in 2D, 1 in 3D: particle volume over particle area.
    pub thickness: f64,
}

/// Work accumulated since t = 0 (J).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Work {
    /// Work done by external particle forces and gravity.
    pub external: f64,
    /// Energy removed by damping.
    pub damping: f64,
    /// Energy dissipated by Coulomb friction on crack faces.
    pub friction: f64,
}

/// One row of energy.csv (J).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Energies {
    /// Kinetic energy.
    pub kinetic: f64,
    /// Material strain energy.
    pub strain: f64,
    /// External work done on the body.
    pub external_work: f64,
    /// Energy removed by damping.
    pub damping_work: f64,
    /// Energy dissipated by plastic flow (zero in an elastic scene).
    pub plastic_work: f64,
    /// Energy dissipated by friction on crack faces (zero without a friction law).
    pub friction_work: f64,
}

impl Energies {
    /// The stored and dissipated energy, K + W + W_p.
    pub fn internal(&self) -> f64 {
        self.kinetic + self.strain + self.plastic_work
    }

    /// The balance E = K + W + W_p - W_ext + W_damp + W_f, constant when energy is
    /// conserved.
    pub fn balance(&self) -> f64 {
        self.internal() - self.external_work + self.damping_work + self.friction_work
    }
}

/// All simulation state.
#[derive(Clone, Debug)]
pub struct World<D: Dim> {
    /// Particle store.
    pub particles: Particles<D>,
    /// Grid store.
    pub grid: Grid<D>,
    /// Particle bins.
    pub tiles: Tiles,
    /// Material table, indexed by the particles' material column.
    pub materials: Vec<Material>,
    /// Scene settings.
    pub settings: Settings<D>,
    /// External particle forces.
    pub loads: Vec<Load<D>>,
    /// Prescribed grid velocities.
    pub bcs: Vec<VelocityBc<D>>,
    /// Simulated time (s).
    pub time: f64,
    /// Steps taken.
    pub step: u64,
    /// Accumulated work.
    pub work: Work,
    /// Explicit cracks and their velocity fields (None in a scene without cracks).
    pub cracks: Option<Cracks<D>>,
    /// The ranks the scene is split across, and this rank's share.
    pub domain: Domain,
}

/// Particles (or grid nodes) per chunk in parallel loops; fixed so reductions do not
/// depend on the thread count.
pub const CHUNK: usize = 1024;

impl<D: Dim> World<D> {
    /// Kinetic and strain energy now, with the accumulated work.
    pub fn energies(&self) -> Energies {
        let p = &self.particles;
        let mats = &self.materials;
        // Exact sums: the energies do not depend on how the particles are split up.
        let mut sums = (0..p.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut s: [ExactSum; 3] = Default::default();
                for i in c * CHUNK..((c + 1) * CHUNK).min(p.len()) {
                    s[0].add(0.5 * p.mass[i] * D::dot(p.v[i], p.v[i]));
                    s[1].add(
                        p.volume[i]
                            * mats[p.material[i] as usize].energy_density(&p.stress[i].to_sym3()),
                    );
                    s[2].add(p.volume[i] * p.plastic_work(i));
                }
                s
            })
            .reduce(Default::default, merge3);
        self.domain.sum(&mut sums);
        let [k, w, wp] = sums.map(|s| s.value());
        Energies {
            kinetic: k,
            strain: w,
            plastic_work: wp,
            external_work: self.work.external,
            damping_work: self.work.damping,
            friction_work: self.work.friction,
        }
    }

    /// With linear shape functions, the particles now in another grid cell than the one
    /// they started in (None with the other shapes). Each crossing of a cell edge jumps a
    /// linear stencil's gradients, and with them the particle's internal force (the
    /// cell-crossing error that GIMP removes, Bardenhagen & Kober 2004). None in a static
    /// scene too, whose stiffness stays on the particles' initial places.
    pub fn cell_crossings(&self) -> Option<usize> {
        if self.settings.shape != ShapeKind::Linear || self.settings.solver == Solver::Static {
            return None;
        }
        let g = &self.grid.geom;
        let cell = |x: D::Vec, a: usize| ((x[a] - g.origin[a]) * g.inv_h[a]).floor();
        let p = &self.particles;
        let moved = (0..p.len())
            .into_par_iter()
            .filter(|&i| (0..D::D).any(|a| cell(p.x[i], a) != cell(p.x0[i], a)))
            .count();
        // Over every rank (a count is exact as a double).
        let mut all = [ExactSum::new()];
        all[0].add(moved as f64);
        self.domain.sum(&mut all);
        Some(all[0].value() as usize)
    }

    /// Bytes held per particle: the particle columns plus the bins (tile and order, 4 bytes
    /// each) and the cached stencil (a 4-byte first node plus the shape's parameters).
    pub fn bytes_per_particle(&self) -> usize {
        let params = StencilCache::per::<D>(self.settings.shape);
        self.particles.bytes_per_particle() + 8 + 4 + 8 * params
    }

    /// Total linear momentum (kg m/s), summed exactly.
    pub fn momentum(&self) -> D::Vec {
        let p = &self.particles;
        let mut sums: [ExactSum; 3] = Default::default();
        for i in 0..p.len() {
            for (a, s) in sums.iter_mut().enumerate().take(D::D) {
                s.add(p.v[i][a] * p.mass[i]);
            }
        }
        self.domain.sum(&mut sums);
        let mut m = D::zero();
        for a in 0..D::D {
            m[a] = sums[a].value();
        }
        m
    }

    /// Total angular momentum about `centre` (kg m^2/s), padded to 3 components, summed
    /// exactly.
    pub fn angular_momentum(&self, centre: D::Vec) -> [f64; 3] {
        let p = &self.particles;
        let mut l: [ExactSum; 3] = Default::default();
        for i in 0..p.len() {
            let c = D::cross(p.x[i] - centre, p.v[i] * p.mass[i]);
            for a in 0..3 {
                l[a].add(c[a]);
            }
        }
        self.domain.sum(&mut l);
        l.map(|s| s.value())
    }
}

/// Merges three exact sums pairwise.
fn merge3(mut a: [ExactSum; 3], b: [ExactSum; 3]) -> [ExactSum; 3] {
    for (a, b) in a.iter_mut().zip(&b) {
        a.merge(b);
    }
    a
}
