//! `mirror`: the image nodes of the B-spline symmetry planes ([`Mirrors`]). What a scatter
//! leaves on an image (mass, momentum, force) is the share the body's mirror half would
//! give the image's source, reflected: it is added there and the image cleared. Once the
//! sources' velocities are set, each image takes its source's, reflected. The half body
//! then moves as the whole symmetric body would, to round-off. The scattering and updating
//! systems call these; a scene without images skips them.

use crate::base::dim::Dim;
use crate::physics::loads::VelocityBc;
use crate::store::grid::Grid;
use crate::store::mirror::{Image, Mirrors, Share};

/// Adds each image's mass, momentum and force (a `p2g` scatter, loads included) to its
/// source's, reflected, and clears the image, keeping what it held as the image's
/// [`Share`]. `gravity` is applied later as g m on the summed mass; the mirror half feels it
/// reflected, so the difference (R g - g) m_image is added to the source's force here.
pub fn fold_scatter<D: Dim>(grid: &mut Grid<D>, gravity: D::Vec) {
    let Grid {
        mirrors,
        mass,
        momentum,
        force,
        ..
    } = grid;
    for (im, share) in mirrors.images.iter().zip(&mut mirrors.shares) {
        let (i, s) = (im.node as usize, im.source as usize);
        let reflect = |v: D::Vec| Mirrors::<D>::reflect(im.sign, v);
        *share = Share {
            mass: std::mem::take(&mut mass[i]),
            momentum: std::mem::replace(&mut momentum[i], D::zero()),
            force: std::mem::replace(&mut force[i], D::zero()),
        };
        mass[s] += share.mass;
        momentum[s] += reflect(share.momentum);
        force[s] += reflect(share.force) + reflected_gravity::<D>(im, gravity, share.mass);
    }
}

/// The force gravity adds to an image's source beyond g times their summed mass, for the
/// image's mass `m`: the mirror half feels gravity reflected, (R g - g) m.
pub fn reflected_gravity<D: Dim>(im: &Image<D::Vec>, gravity: D::Vec, m: f64) -> D::Vec {
    (Mirrors::<D>::reflect(im.sign, gravity) - gravity) * m
}

/// Adds each image's force (a later scatter of internal forces) to its source's,
/// reflected, and to its [`Share`], and clears the image.
pub fn fold_force<D: Dim>(grid: &mut Grid<D>) {
    let Mirrors { images, shares, .. } = &mut grid.mirrors;
    for (im, share) in images.iter().zip(shares) {
        share.force += grid.force[im.node as usize];
    }
    fold_images::<D>(images, &mut grid.force);
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

/// Adds to each symmetry plane's reaction the part of the force across it that reaches the
/// body through the images past it. Over the whole grid the particles' internal forces sum
/// to zero, so the force across the plane is the sum over every node the body reaches of
/// its own residual rho = m a - f (the supports' reactions where held, zero at free nodes).
/// A free source's folded equation holds its residual less its image's on the plane's
/// normal (the reflection flips the image's there), so the two are equal, not zero, and the
/// plane's own nodes miss 2 rho of each image past it. `residual(k)` is image k's own rho
/// (explicit: m a - f with the damping and gravity; static: K u - f), booked at its
/// [`Credit`]s.
pub fn credit_reactions<D: Dim>(
    mirrors: &Mirrors<D>,
    bcs: &mut [VelocityBc<D>],
    residual: impl Fn(usize) -> D::Vec,
) {
    for c in &mirrors.credits {
        let rho = residual(c.image as usize);
        let a = c.axis as usize;
        bcs[c.boundary as usize].reaction[c.place as usize][a] += 2.0 * rho[a];
    }
}
