//! `mirror`: the image nodes of the B-spline symmetry planes ([`Mirrors`]). What a scatter
//! leaves on an image (mass, momentum, force) is the share the body's mirror half would
//! give the image's source, reflected: it is added there and the image cleared. Once the
//! sources' velocities are set, each image takes its source's, reflected. The half body
//! then moves as the whole symmetric body would, to round-off. The scattering and updating
//! systems call these; a scene without images skips them.

use crate::base::dim::Dim;
use crate::store::grid::Grid;
use crate::store::mirror::{Image, Mirrors};

/// Adds each image's mass, momentum and force (a `p2g` scatter, loads included) to its
/// source's, reflected, and clears the image. `gravity` is applied later as g m on the
/// summed mass; the mirror half feels it reflected, so the difference (R g - g) m_image is
/// added to the source's force here.
pub fn fold_scatter<D: Dim>(grid: &mut Grid<D>, gravity: D::Vec) {
    let Grid {
        mirrors,
        mass,
        momentum,
        force,
        ..
    } = grid;
    for im in &mirrors.images {
        let (i, s) = (im.node as usize, im.source as usize);
        let reflect = |v: D::Vec| Mirrors::<D>::reflect(im.sign, v);
        let m = std::mem::take(&mut mass[i]);
        mass[s] += m;
        let p = std::mem::replace(&mut momentum[i], D::zero());
        momentum[s] += reflect(p);
        let f = std::mem::replace(&mut force[i], D::zero());
        force[s] += reflect(f) + (reflect(gravity) - gravity) * m;
    }
}

/// Adds each image's force (a later scatter of internal forces) to its source's,
/// reflected, and clears the image.
pub fn fold_force<D: Dim>(grid: &mut Grid<D>) {
    fold_images::<D>(&grid.mirrors.images, &mut grid.force);
}

/// Adds each image's momentum (the remap of the particles' momenta) to its source's,
/// reflected, and clears the image.
pub fn fold_momentum<D: Dim>(grid: &mut Grid<D>) {
    fold_images::<D>(&grid.mirrors.images, &mut grid.momentum);
}

/// Adds each image's entry of `column` to its source's, reflected, and clears the image
/// (a force: the transpose of [`reflect_images`]).
pub fn fold_images<D: Dim>(images: &[Image<D::Vec>], column: &mut [D::Vec]) {
    for im in images {
        let v = std::mem::replace(&mut column[im.node as usize], D::zero());
        column[im.source as usize] += Mirrors::<D>::reflect(im.sign, v);
    }
}

/// Gives each image its source's velocity, reflected, and, when `accel`, its acceleration.
pub fn reflect_velocity<D: Dim>(grid: &mut Grid<D>, accel: bool) {
    reflect_images::<D>(&grid.mirrors.images, &mut grid.velocity);
    if accel {
        reflect_images::<D>(&grid.mirrors.images, &mut grid.accel);
    }
}

/// Gives each image's entry of `column` its source's, reflected (a per-entry displacement
/// or velocity).
pub fn reflect_images<D: Dim>(images: &[Image<D::Vec>], column: &mut [D::Vec]) {
    for im in images {
        column[im.node as usize] = Mirrors::<D>::reflect(im.sign, column[im.source as usize]);
    }
}
