//! Probes: particle averages (or a boundary's reaction) sampled every step.

use crate::base::dim::Dim;
use crate::base::exact_sum::ExactSum;
use crate::base::sym::SymTensor;
use crate::ranks::ABSENT;
use crate::ranks::domain::Domain;
use crate::store::particles::Particles;
use crate::store::world::World;
use serde::Serialize;

/// What a probe averages.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProbeQty {
    /// Displacement component (m).
    Displacement,
    /// Velocity component (m/s).
    Velocity,
    /// Position component (m).
    Position,
    /// Stress component (Pa).
    Stress,
    /// Strain component (elastic plus plastic).
    Strain,
    /// Opening along the component's axis (m): the mean displacement of the particles
    /// initially beyond the probe's centroid on that axis minus that of those short of it;
    /// across a crack, a clip gauge (e.g. the crack-mouth opening, CMOD).
    Opening,
    /// Largest initial distance (m) from the probe's centre of a particle that has yielded
    /// (0 while none has): the radius of a plastic zone spreading from a bore or a load.
    PlasticRadius,
    /// Force component (N; in 2D for the scene's thickness) that the prescribed-velocity
    /// nodes inside the probe's region exerted on the body over the last step: a support's
    /// or a grip's reaction, the load of a load-displacement curve.
    Reaction,
}

/// Average of one component over a fixed particle set.
#[derive(Clone, Debug)]
pub struct Probe {
    /// Name.
    pub name: String,
    /// Particles averaged (none for a reaction; split across ranks: this rank's index, or
    /// `ABSENT`).
    pub particles: Vec<u32>,
    /// Split across ranks: the averaged particles' ids in the whole scene (empty on one
    /// rank).
    pub ids: Vec<u32>,
    /// A reaction's nodes: (index of the boundary, the node's place in its node list).
    pub supports: Vec<(u32, u32)>,
    /// Quantity.
    pub qty: ProbeQty,
    /// Component index (0..3 for vectors, 0..6 in xx, yy, zz, yz, xz, xy order for tensors).
    pub comp: usize,
    /// Initial centroid of the particles (m); for a plastic radius, the centre of its disc
    /// or ball region; for a reaction, the centroid of its nodes.
    pub centre: [f64; 3],
}

impl Probe {
    /// Current value.
    pub fn sample<D: Dim>(&self, world: &World<D>) -> f64 {
        let (p, materials) = (&world.particles, &world.materials);
        match self.qty {
            ProbeQty::Opening => return self.opening(p, &world.domain),
            ProbeQty::PlasticRadius => return self.plastic_radius(p, &world.domain),
            ProbeQty::Reaction => {
                let bcs = &world.bcs;
                let force = |&(b, k): &(u32, u32)| bcs[b as usize].reaction[k as usize];
                // Only the node's owner has its reaction (split across ranks).
                let mut sum = ExactSum::new();
                for s in &self.supports {
                    let node = bcs[s.0 as usize].nodes[s.1 as usize] as usize;
                    if world.domain.owns_node(node) {
                        sum.add(force(s)[self.comp]);
                    }
                }
                world.domain.sum(std::slice::from_mut(&mut sum));
                return sum.value();
            }
            _ => {}
        }
        let mut sum = ExactSum::new();
        for &i in &self.particles {
            if i == ABSENT {
                continue;
            }
            let i = i as usize;
            sum.add(match self.qty {
                ProbeQty::Displacement => p.displacement(i)[self.comp],
                ProbeQty::Velocity => p.v[i][self.comp],
                ProbeQty::Position => p.x[i][self.comp],
                ProbeQty::Stress => p.stress[i].to_sym3().to_array()[self.comp],
                ProbeQty::Strain => {
                    let elastic = materials[p.material[i] as usize].strain(&p.stress[i].to_sym3());
                    let strain = match p.plastic_strain.get(i) {
                        Some(ep) => elastic + ep.to_sym3(),
                        None => elastic,
                    };
                    strain.to_array()[self.comp]
                }
                ProbeQty::Opening | ProbeQty::PlasticRadius | ProbeQty::Reaction => {
                    unreachable!("sampled by their own methods")
                }
            });
        }
        world.domain.sum(std::slice::from_mut(&mut sum));
        sum.value() / self.particles.len() as f64
    }

    /// The [`ProbeQty::Opening`] sample.
    fn opening<D: Dim>(&self, p: &Particles<D>, domain: &Domain) -> f64 {
        let c = self.comp;
        // Per side: the displacements' sum and the count (exact, over every rank).
        let mut sides: [ExactSum; 4] = Default::default();
        for &i in self.particles.iter().filter(|&&i| i != ABSENT) {
            let i = i as usize;
            let side = 2 * usize::from(p.x0[i][c] > self.centre[c]);
            sides[side].add(p.displacement(i)[c]);
            sides[side + 1].add(1.0);
        }
        domain.sum(&mut sides);
        let [s0, n0, s1, n1] = sides.map(|s| s.value());
        s1 / n1 - s0 / n0
    }

    /// The [`ProbeQty::PlasticRadius`] sample; 0 in a scene without plastic columns.
    fn plastic_radius<D: Dim>(&self, p: &Particles<D>, domain: &Domain) -> f64 {
        let mut radius = 0.0f64;
        for &i in self.particles.iter().filter(|&&i| i != ABSENT) {
            let i = i as usize;
            if p.hardened.get(i).is_some_and(|h| h.equivalent > 0.0) {
                let x = D::to_xyz(p.x0[i]);
                let d = [0, 1, 2].map(|a| x[a] - self.centre[a]);
                radius = radius.max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
            }
        }
        domain.max(radius)
    }
}
