//! `crack_advect`: crack vertices move with the centre-of-mass velocity of the nodal fields,
//! and the top and bottom crack surfaces with the fields above and below the crack (Guo &
//! Nairn 3D (2006) Eqs. 21-23; 2D (2004) section 2.2), which gives the crack opening.

use crate::crack::{Cracks, Fields};
use crate::dim::Dim;
use crate::shape::{ShapeKind, Stencil};
use crate::world::World;

/// Centre-of-mass velocity at node `n` (Eq. 23), and the momenta and masses of its fields
/// above and below crack `c`.
fn node_fields<D: Dim>(
    n: usize,
    c: usize,
    mass: &[f64],
    velocity: &[D::Vec],
    fields: &Fields,
    tol: f64,
) -> (D::Vec, [(D::Vec, f64); 2]) {
    let (mut m, mut mv) = (mass[n], velocity[n] * mass[n]);
    for r in fields.rows_of(n as u32) {
        m += mass[r];
        mv += velocity[r] * mass[r];
    }
    if m <= tol {
        return (D::zero(), [(D::zero(), 0.0); 2]);
    }
    let side = |s: i8| {
        let e = fields.side_entry(n, c, s);
        (velocity[e] * mass[e], mass[e])
    };
    (mv * (1.0 / m), [side(1), side(-1)])
}

/// Moves every crack vertex and both surfaces over the step, interpolating the updated
/// nodal velocities with linear shape functions (crack vertices are massless points).
/// Vertices outside the grid do not move.
pub fn run<D: Dim>(world: &mut World<D>) {
    let Some(Cracks {
        x: xs,
        top,
        bottom,
        cracks,
        fields,
        ..
    }) = world.cracks.as_mut()
    else {
        return;
    };
    let dt = world.settings.dt;
    let tol = world.settings.mass_tol;
    let g = &world.grid;
    let geom = &g.geom;
    for (c, crack) in cracks.iter().enumerate() {
        for k in crack.vertices.clone() {
            let x = xs[k];
            if !geom.fits(ShapeKind::Linear, x, D::zero()) {
                continue;
            }
            let mut st = Stencil::<2> {
                base: [0; 3],
                w: [[1.0, 0.0, 0.0]; 3],
                dw: [[0.0; 3]; 3],
            };
            for a in 0..D::D {
                let xi = (x[a] - geom.origin[a]) * geom.inv_h[a];
                let (b, w, dw) = ShapeKind::Linear.axis(xi, 0.0, geom.inv_h[a]);
                st.base[a] = b;
                st.w[a] = w;
                st.dw[a] = dw;
            }
            let mut cm = D::zero();
            let mut sides = [(D::zero(), 0.0); 2];
            st.for_each::<D>(&geom.stride, |n, w, _| {
                let (v, f) = node_fields::<D>(n, c, &g.mass, &g.velocity, fields, tol);
                cm += v * w;
                for (s, (p, m)) in sides.iter_mut().zip(f) {
                    s.0 += p * w;
                    s.1 += m * w;
                }
            });
            // Each surface moves with the mass-weighted velocity of its side's fields, so a
            // field holding a sliver of mass (and a meaningless velocity) cannot drag it.
            let surface = |(p, m): (D::Vec, f64)| if m > tol { p * (1.0 / m) } else { cm };
            xs[k] += cm * dt;
            top[k] += surface(sides[0]) * dt;
            bottom[k] += surface(sides[1]) * dt;
        }
    }
}
