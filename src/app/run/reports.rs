//! The fracture reports of summary.json: path dependence of J, the tubes around a 3D front
//! that did not fit inside the body, and how far the growing tips got.

use crate::base::dim::Dim;
use crate::fracture::plan::FracturePlan;
use crate::io::output::summary::{
    ContourReport, GrowthReport, NodeLineReport, ParticlesOnReport, PathReport, ProbeReport,
    RanksReport, SplitBoundaryReport, TipLinesReport, TubeReport,
};
use crate::physics::growth::Stopped;
use crate::record::history::{History, last_rows, path_difference, path_tips};
use crate::record::probe::Probe;
use crate::store::crack::{on_node_lines, particles_on, tips_on_lines};
use crate::store::world::World;

/// The path-dependence report of summary.json: every crack tip against every compared
/// contour; along a 3D front, the worst of its vertices against every compared tube.
pub(super) fn paths<D: Dim>(
    world: &World<D>,
    plan: Option<&FracturePlan>,
    history: &History,
) -> Vec<PathReport> {
    let (Some(plan), Some(cracks)) = (plan, &world.cracks) else {
        return Vec::new();
    };
    let topo = &cracks.topology;
    // (crack, tip label, the tips reported together)
    let groups: Vec<(u32, String, Vec<u32>)> = if D::D == 2 {
        (topo.fronts().iter())
            .map(|f| {
                (
                    f.crack as u32,
                    ["start", "end"][f.end as usize].into(),
                    vec![f.end],
                )
            })
            .collect()
    } else {
        (0..topo.cracks().len() as u32)
            .map(|c| (c, "front (worst vertex)".into(), path_tips(history, c)))
            .filter(|g| !g.2.is_empty())
            .collect()
    };
    let mut out = Vec::new();
    for (c, label, tips) in groups {
        for &n in &plan.compare {
            let diff = |area| {
                tips.iter()
                    .map(|&t| {
                        let (main, n) = (plan.contour as u32, n as u32);
                        path_difference(history, c, t, main, n, plan.compare_from, area)
                    })
                    .try_fold(0.0, |worst: f64, d| d.map(|d| worst.max(d)))
            };
            out.push(PathReport {
                crack: topo.cracks()[c as usize].name.clone(),
                tip: label.clone(),
                main: plan.contour as u32,
                contour: n as u32,
                from: plan.compare_from,
                with_area: diff(true),
                without_area: diff(false),
            });
        }
    }
    out
}

/// The tubes of the last measurement along each 3D front that were shrunk to stay inside
/// the body, or that did not fit at all (J and K NaN there).
pub(super) fn tubes<D: Dim>(
    world: &World<D>,
    plan: Option<&FracturePlan>,
    history: &History,
) -> Vec<TubeReport> {
    let (Some(plan), Some(cracks), true) = (plan, &world.cracks, D::D == 3) else {
        return Vec::new();
    };
    let h = (0..D::D).map(|a| world.grid.geom.h[a]).fold(0.0, f64::max);
    let asked = plan.domain * h;
    let mut out = Vec::new();
    for (c, crack) in cracks.topology.cracks().iter().enumerate() {
        let Some(mut mine) = last_rows(history, c as u32) else {
            continue;
        };
        mine.sort_by_key(|t| t.tip);
        let unfitted: Vec<u32> = (mine.iter())
            .filter(|t| t.domain == 0.0)
            .map(|t| t.tip)
            .collect();
        let shrunk: Vec<u32> = (mine.iter())
            .filter(|t| t.domain > 0.0 && t.domain < asked)
            .map(|t| t.tip)
            .collect();
        if !(unfitted.is_empty() && shrunk.is_empty()) {
            out.push(TubeReport {
                crack: crack.name.clone(),
                radius: asked,
                vertices: mine.len(),
                shrunk: ranges(&shrunk),
                unfitted: ranges(&unfitted),
            });
        }
    }
    out
}

/// The 2D tips whose last measurement found no J (its contour did not cross the crack).
pub(super) fn contours<D: Dim>(
    world: &World<D>,
    plan: Option<&FracturePlan>,
    history: &History,
) -> Vec<ContourReport> {
    let (Some(plan), Some(cracks), true) = (plan, &world.cracks, D::D == 2) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (c, crack) in cracks.topology.cracks().iter().enumerate() {
        let Some(mut mine) = last_rows(history, c as u32) else {
            continue;
        };
        mine.sort_by_key(|t| t.tip);
        out.extend(
            mine.iter()
                .filter(|t| t.j[0].is_nan())
                .map(|t| ContourReport {
                    crack: crack.name.clone(),
                    tip: if t.tip == 0 { "start" } else { "end" }.to_string(),
                    cells: plan.contour,
                }),
        );
    }
    out
}

/// Sorted vertex numbers as ranges: 0-2, 7, 61-63.
fn ranges(v: &[u32]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut k = 0;
    while k < v.len() {
        let mut e = k;
        while e + 1 < v.len() && v[e + 1] == v[e] + 1 {
            e += 1;
        }
        out.push(if e == k {
            v[k].to_string()
        } else {
            format!("{}-{}", v[k], v[e])
        });
        k = e + 1;
    }
    out.join(", ")
}

/// Every probe's last sample.
pub(super) fn probes(probes: &[Probe], h: &History) -> Vec<ProbeReport> {
    (probes.iter().zip(&h.probes))
        .map(|(p, samples)| ProbeReport {
            name: p.name.clone(),
            quantity: p.qty,
            last: samples.last().copied(),
        })
        .collect()
}

/// Every growing 2D tip: where it is, how far it grew, and why it stopped, if it did.
pub(super) fn growth<D: Dim>(world: &World<D>) -> Vec<GrowthReport> {
    let Some(cracks) = &world.cracks else {
        return Vec::new();
    };
    let topo = &cracks.topology;
    (topo.fronts().iter().zip(&cracks.tips))
        .filter_map(|(f, st)| {
            let crack = &topo.cracks()[f.crack as usize];
            let g = crack.growth?;
            let at = |v: &u32| D::to_xyz(cracks.geometry.x[*v as usize]);
            let n = f.vertices.len() as f64;
            let x = (f.vertices.iter().map(at))
                .fold([0.0; 3], |s, x| [0, 1, 2].map(|a| s[a] + x[a] / n));
            let tip = if D::D == 3 {
                "front"
            } else {
                ["start", "end"][f.end as usize]
            };
            Some(GrowthReport {
                crack: crack.name.clone(),
                tip: tip.into(),
                x: [x[0], x[1]],
                grown: st.grown,
                started: (!st.started.is_nan()).then_some(st.started),
                cycles: g.paris.map(|_| st.cycles),
                stopped: Stopped::from_code(st.stopped).map(|s| s.describe().into()),
            })
        })
        .collect()
}

/// The moving velocity boundaries with nodes that carried a field per crack side at the
/// last step (a boundary prescribes every field of its nodes). A still one is left out: a
/// symmetry plane or a grip holding both faces is what it is meant to do.
pub(super) fn split_boundaries<D: Dim>(world: &World<D>) -> Vec<SplitBoundaryReport> {
    let Some(cracks) = &world.cracks else {
        return Vec::new();
    };
    let fields = &cracks.scratch.fields;
    let moving = |bc: &&crate::physics::loads::VelocityBc<D>| {
        (0..D::D).any(|a| bc.axes[a] && bc.velocity[a] != 0.0)
    };
    (world.bcs.iter().enumerate())
        .filter(|(_, bc)| moving(bc))
        .map(|(boundary, bc)| {
            let split = |n: &&u32| !fields.rows_of(**n).is_empty();
            let nodes = bc.nodes.iter().filter(split).count();
            SplitBoundaryReport { boundary, nodes }
        })
        .filter(|r| r.nodes > 0)
        .collect()
}

/// The cracks that lie on a line or plane of grid nodes as the world stands.
pub fn node_lines<D: Dim>(world: &World<D>) -> Vec<NodeLineReport> {
    let Some(cracks) = &world.cracks else {
        return Vec::new();
    };
    (on_node_lines(cracks, &world.grid.geom).into_iter())
        .map(|n| NodeLineReport {
            crack: cracks.topology.cracks()[n.crack].name.clone(),
            axis: ["x", "y", "z"][n.axis].into(),
            at: n.at,
            share: n.share,
        })
        .collect()
}

/// The cracks that pass through particle centres as the world stands.
pub fn particles_on_cracks<D: Dim>(world: &World<D>) -> Vec<ParticlesOnReport> {
    let Some(cracks) = &world.cracks else {
        return Vec::new();
    };
    let geom = &world.grid.geom;
    let mut cell = [f64::INFINITY; 3];
    (0..D::D).for_each(|a| cell[a] = geom.h[a]);
    let found = particles_on(cracks, &world.particles.x, cell);
    (every_rank(world, found).into_iter())
        .map(|(c, particles)| ParticlesOnReport {
            crack: cracks.topology.cracks()[c].name.clone(),
            particles,
        })
        .collect()
}

/// Per-crack counts `(crack, count)` of this rank's particles added over every rank, the
/// cracks with none left out.
fn every_rank<D: Dim>(world: &World<D>, mine: Vec<(usize, usize)>) -> Vec<(usize, usize)> {
    let Some(cracks) = &world.cracks else {
        return mine;
    };
    let mut counts = vec![0.0; cracks.topology.cracks().len()];
    mine.iter().for_each(|&(c, n)| counts[c] = n as f64);
    world.domain.add_rows(&mut counts, 1);
    (counts.iter().enumerate())
        .filter(|c| *c.1 > 0.0)
        .map(|(c, &n)| (c, n as usize))
        .collect()
}

/// The cracks whose tips or front edges lie on particle-node lines as the world stands.
pub fn tips_on_particle_lines<D: Dim>(world: &World<D>) -> Vec<TipLinesReport> {
    let Some(cracks) = &world.cracks else {
        return Vec::new();
    };
    let p = &world.particles;
    let found = tips_on_lines(
        cracks,
        &p.x,
        &p.half,
        &world.grid.geom,
        world.settings.shape,
    );
    (every_rank(world, found).into_iter())
        .map(|(c, lines)| TipLinesReport {
            crack: cracks.topology.cracks()[c].name.clone(),
            lines,
        })
        .collect()
}

/// How a split run was divided and what its ranks sent (None on one rank); every rank
/// calls it.
pub(super) fn ranks<D: Dim>(world: &World<D>, steps: u64) -> Option<RanksReport> {
    let comm = &world.domain.comm;
    if !comm.is_split() {
        return None;
    }
    let [messages, bytes, collectives, inside] = comm.traffic();
    let peak = crate::io::output::summary::peak_resident_bytes().unwrap_or(0);
    let mine = [
        world.particles.len() as u64,
        messages,
        bytes,
        collectives,
        inside,
        peak,
    ];
    let all: Vec<[u64; 6]> = (comm.all_gather(bytemuck::cast_slice(&mine).to_vec()).iter())
        .map(|b| bytemuck::pod_read_unaligned(b))
        .collect();
    let per_step = |k: usize| all.iter().map(move |r| r[k] as f64 / steps.max(1) as f64);
    let mean = |k: usize| per_step(k).sum::<f64>() / all.len() as f64;
    let most = |k: usize| per_step(k).fold(0.0, f64::max);
    Some(RanksReport {
        ranks: all.len(),
        particles: [
            all.iter().map(|r| r[0] as usize).min().unwrap_or(0),
            all.iter().map(|r| r[0] as usize).max().unwrap_or(0),
        ],
        messages_per_step: [mean(1), most(1)],
        bytes_per_step: [mean(2), most(2)],
        collectives_per_step: mean(3),
        mpi_seconds: [
            all.iter().map(|r| r[4] as f64 * 1e-9).sum::<f64>() / all.len() as f64,
            all.iter().map(|r| r[4] as f64 * 1e-9).fold(0.0, f64::max),
        ],
        rebalances: world.domain.rebalances,
        peak_resident_bytes: [
            all.iter().map(|r| r[5]).sum::<u64>() / all.len() as u64,
            all.iter().map(|r| r[5]).max().unwrap_or(0),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::ranges;

    #[test]
    fn vertex_ranges() {
        assert_eq!(ranges(&[0, 1, 2, 7, 61, 62, 63]), "0-2, 7, 61-63");
        assert_eq!(ranges(&[4]), "4");
        assert_eq!(ranges(&[]), "");
    }
}
