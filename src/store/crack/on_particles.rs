//! Cracks that pass through particle centres. Which side of a crack such a particle lies on
//! is decided by the round-off of the crack's vertices, and the particle's volume, which
//! straddles the crack, goes whole to that side: J and K then depend on round-off. The
//! penny turned 45 degrees about z passes through 224 particle centres of its lattice and
//! reads K_I +6.1 % static and +2.7 % explicit at its worst front vertex; moved 0.1 mm off
//! them it reads +4.1 % both ways (docs/static-solver.md).

use super::{Cracks, ElementBins};
use crate::base::dim::Dim;
use rayon::prelude::*;

/// A particle centre within this fraction of the grid's smallest cell spacing of a crack
/// element lies on it: far below any spacing a scene would use, far above round-off.
const ON: f64 = 1e-7;

/// Per crack (by index), the number of particle centres `x` that lie on it, for the cracks
/// with any; `cell` is the grid's cell size per axis (m).
pub fn particles_on<D: Dim>(
    cracks: &Cracks<D>,
    x: &[D::Vec],
    cell: [f64; 3],
) -> Vec<(usize, usize)> {
    let topo = &cracks.topology;
    let verts = &cracks.geometry.x;
    let elems = topo.elems();
    let tol = ON * cell[..D::D].iter().copied().fold(f64::INFINITY, f64::min);
    (0..topo.cracks().len())
        .filter_map(|c| {
            let mine = |e: usize| topo.elem_crack()[e] as usize == c;
            let bins = ElementBins::new::<D>(verts, elems, mine, cell, 0);
            let on = (x.par_iter())
                .filter(|&&p| bins.touches::<D>(p, verts, elems, tol))
                .count();
            (on > 0).then_some((c, on))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::dim::{D2, D3};
    use crate::store::crack::Contact;
    use glam::{DVec2, DVec3};

    /// Particles at the quarter points of 1 mm cells, x and y in 0..10 mm.
    fn lattice() -> Vec<DVec2> {
        (0..20)
            .flat_map(|j| (0..20).map(move |i| DVec2::new(i as f64, j as f64) * 5e-4 + 2.5e-4))
            .collect()
    }

    /// A crack of four segments from (1, y) mm to (9, y) mm.
    fn line(y: f64) -> Cracks<D2> {
        let mut c = Cracks::<D2>::default();
        let segments: Vec<[u32; 2]> = (0..4).map(|k| [k, k + 1]).collect();
        c.topology
            .add_crack("c".into(), Contact::OPEN, None, 5, &segments, &[]);
        c.geometry.x = (0..5)
            .map(|k| DVec2::new(1e-3 + 2e-3 * k as f64, y))
            .collect();
        c
    }

    /// Along a row of particles the crack holds the 16 centres from 1 to 9 mm (x = 1.25 ..
    /// 8.75 mm); half a spacing off, none; a crack's end on a centre counts it.
    #[test]
    fn a_crack_along_a_particle_row_holds_its_centres() {
        let cell = [1e-3, 1e-3, f64::INFINITY];
        assert_eq!(
            particles_on(&line(4.75e-3), &lattice(), cell),
            vec![(0, 16)]
        );
        assert!(particles_on(&line(5e-3), &lattice(), cell).is_empty());
        assert!(particles_on(&line(4.75e-3 + 1e-8), &lattice(), cell).is_empty());
    }

    /// A triangle in the plane x + y = 5 mm holds the centres that lie on that plane inside it.
    #[test]
    fn an_oblique_triangle_holds_the_centres_on_its_plane() {
        let mut c = Cracks::<D3>::default();
        c.topology
            .add_crack("t".into(), Contact::OPEN, None, 3, &[[0, 1, 2]], &[]);
        c.geometry.x = vec![
            DVec3::new(0.0, 5e-3, 0.0),
            DVec3::new(5e-3, 0.0, 0.0),
            DVec3::new(2.5e-3, 2.5e-3, 5e-3),
        ];
        let h = 5e-4;
        let x: Vec<DVec3> = (0..10)
            .flat_map(|k| (0..10).flat_map(move |j| (0..10).map(move |i| [i, j, k])))
            .map(|[i, j, k]| DVec3::new(i as f64, j as f64, k as f64) * h + h / 2.0)
            .collect();
        // The exact count: centres with x + y = 5 mm inside the triangle, whose z at the
        // point (x, y) on the edge from vertex 0 to 1 reaches 5 mm at its middle.
        let inside = |p: &DVec3| {
            let s = p.x / 5e-3;
            (p.x + p.y - 5e-3).abs() < 1e-12 && p.z <= 5e-3 * (1.0 - (2.0 * s - 1.0).abs())
        };
        let want = x.iter().filter(|p| inside(p)).count();
        assert!(want > 10);
        assert_eq!(particles_on(&c, &x, [1e-3; 3]), vec![(0, want)]);
    }
}
