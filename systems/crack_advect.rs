//! `crack_advect`: crack vertices move with the centre-of-mass velocity of the nodal fields,
//! and the top and bottom crack surfaces with the fields above and below the crack (Guo &
//! Nairn 3D (2006) Eqs. 21-23; 2D (2004) section 2.2), which gives the crack opening.

use crate::base::dim::Dim;
use crate::physics::shape::{ShapeKind, Stencil};
use crate::ranks::domain::Domain;
use crate::store::crack::{Cracks, Fields, Positions};
use crate::store::grid::Grid;
use crate::store::tiles::Tiles;
use crate::store::world::{Update, World};

/// Momentum and mass at node `n`, all fields together (Eq. 23's centre of mass), and of its
/// fields above and below the crack of colour `color`; zero for fields lighter than
/// `sliver`. `momentum` gives each entry's momentum.
fn node_fields<D: Dim>(
    n: usize,
    color: u8,
    mass: &[f64],
    momentum: &impl Fn(usize) -> D::Vec,
    fields: &Fields,
    sliver: f64,
) -> [(D::Vec, f64); 3] {
    let (mut m, mut mv) = (mass[n], momentum(n));
    let rows = fields.rows_of(n as u32);
    for r in rows.clone() {
        m += mass[r];
        mv += momentum(r);
    }
    if m <= sliver {
        return [(D::zero(), 0.0); 3];
    }
    let side = |s: i8| {
        let e = fields.side_entry_in(rows.clone(), n, color, s);
        if mass[e] > sliver {
            (momentum(e), mass[e])
        } else {
            (D::zero(), 0.0)
        }
    };
    [(mv, m), side(1), side(-1)]
}

/// Moves every crack vertex and both surfaces over the step, interpolating the updated
/// nodal velocities with linear shape functions (crack vertices are massless points).
/// Vertices outside the grid do not move.
pub fn run<D: Dim>(world: &mut World<D>) {
    let dt = world.settings.dt;
    // After the momentum remap (USL, USAVG) the grid momenta are the particles' updated
    // momenta, whose mass-weighted average is the material's velocity. The updated nodal
    // velocities p/m + a dt are not, at a field holding part of a few particles near a
    // tip: its share of their stress leaves it an unbalanced force that their other nodes
    // balance, and a dt f/m ran at 0.7 m/s on a damped inclined crack at rest, walking the
    // tip (and the interaction integral's K with it) by 1 % per 200 us.
    let remapped = world.settings.update != Update::Usf;
    let g = &world.grid;
    let momentum = |e: usize| {
        if remapped {
            g.momentum[e]
        } else {
            g.velocity[e] * g.mass[e]
        }
    };
    let mover = Mover {
        grid: g,
        tiles: &world.tiles,
        domain: &world.domain,
        sliver: world.settings.sliver_mass,
    };
    mover.advect(world.cracks.as_mut(), momentum, dt);
}

/// Moves every crack vertex and both surfaces by a static load step's displacement:
/// `moved` holds, per grid entry, the mass-weighted sum of its particles' displacements
/// over the step (a momentum with dt = 1).
pub fn displace<D: Dim>(world: &mut World<D>, moved: &[D::Vec]) {
    let g = &world.grid;
    let mover = Mover {
        grid: g,
        tiles: &world.tiles,
        domain: &world.domain,
        sliver: world.settings.sliver_mass,
    };
    mover.advect(world.cracks.as_mut(), |e| moved[e], 1.0);
}

/// A crack vertex's new place and its surfaces' (the vertex's index first).
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Moved<D: Dim> {
    k: u64,
    x: D::Vec,
    top: D::Vec,
    bottom: D::Vec,
}

// SAFETY: a u64 and three vectors of f64 (2 or 3 each): no padding, and every bit pattern
// is valid.
unsafe impl<D: Dim> bytemuck::Zeroable for Moved<D> {}
// SAFETY: as above; `D::Vec` is Pod (a DVec2 or DVec3).
unsafe impl<D: Dim> bytemuck::Pod for Moved<D> {}

/// What moving the cracks reads: the grid, and who moves which vertex.
struct Mover<'a, D: Dim> {
    grid: &'a Grid<D>,
    tiles: &'a Tiles,
    /// Split across ranks, the rank owning a vertex's tile moves it (its nodes hold the
    /// sums one rank would) and every rank takes the new places.
    domain: &'a Domain,
    /// Fields this light or lighter are left out (kg).
    sliver: f64,
}

impl<D: Dim> Mover<'_, D> {
    /// Moves the cracks by `dt` times the mass-weighted velocity (`momentum` per entry over
    /// the grid's masses) at each vertex.
    fn advect(&self, cracks: Option<&mut Cracks<D>>, momentum: impl Fn(usize) -> D::Vec, dt: f64) {
        let Some(Cracks {
            topology,
            geometry: Positions {
                x: xs, top, bottom, ..
            },
            scratch,
            ..
        }) = cracks
        else {
            return;
        };
        let (g, sliver) = (self.grid, self.sliver);
        let geom = &g.geom;
        let fields = &scratch.fields;
        // One rank moves each vertex as it comes; split, every rank takes the moves.
        let split = self.domain.is_split();
        let mut mine = Vec::new();
        for (c, crack) in topology.cracks().iter().enumerate() {
            let color = scratch.color(c);
            for k in crack.vertices.iter().map(|&k| k as usize) {
                let x = xs[k];
                if !geom.fits(ShapeKind::Linear, x, D::zero()) {
                    continue;
                }
                let mut st = Stencil::<2> {
                    first: 0,
                    w: [[1.0, 0.0, 0.0]; 3],
                    dw: [[0.0; 3]; 3],
                };
                let mut cell = [0; 3];
                for a in 0..D::D {
                    let xi = (x[a] - geom.origin[a]) * geom.inv_h[a];
                    let (b, w, dw) = ShapeKind::Linear.axis(xi, 0.0, geom.inv_h[a]);
                    st.first += b * geom.stride[a];
                    st.w[a] = w;
                    st.dw[a] = dw;
                    cell[a] = b.min(geom.cells[a] - 1);
                }
                if split && !self.domain.owns_tile(self.tiles.tile_of_cell(cell)) {
                    continue;
                }
                let mut sums = [(D::zero(), 0.0); 3];
                st.for_each::<D>(&geom.stride, |n, w, _| {
                    let f = node_fields::<D>(n, color, &g.mass, &momentum, fields, sliver);
                    for (s, (p, m)) in sums.iter_mut().zip(f) {
                        s.0 += p * w;
                        s.1 += m * w;
                    }
                });
                // Mass-weighted velocities (momentum over mass), where Eqs. 22-23 weight the
                // nodes' velocities by the shape functions alone: a node holding a sliver of
                // mass has a meaningless velocity, and with plain weights it threw crack
                // vertices and surfaces off (a crack end outside the body ran at tens of
                // m/s). The crack moves with the centre of mass; each surface with its side's
                // fields, or with the crack where its side has no mass.
                let velocity =
                    |(p, m): (D::Vec, f64)| if m > 0.0 { p * (1.0 / m) } else { D::zero() };
                let cm = velocity(sums[0]);
                let surface = |s: (D::Vec, f64)| if s.1 > 0.0 { velocity(s) } else { cm };
                let moved = Moved::<D> {
                    k: k as u64,
                    x: x + cm * dt,
                    top: top[k] + surface(sums[1]) * dt,
                    bottom: bottom[k] + surface(sums[2]) * dt,
                };
                if split {
                    mine.push(moved);
                } else {
                    (xs[k], top[k], bottom[k]) = (moved.x, moved.top, moved.bottom);
                }
            }
        }
        for m in self.domain.in_order(mine, |m| m.k) {
            let k = m.k as usize;
            (xs[k], top[k], bottom[k]) = (m.x, m.top, m.bottom);
        }
    }
}
