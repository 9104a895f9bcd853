//! Symmetry planes on quadratic B-splines: a quarter of a body held by two planes moves as
//! the whole body under the mirrored loads does, explicit and static, in 2D and 3D. The
//! whole body is the independent answer: by symmetry its quarter's particles must follow
//! the same paths, to round-off. Before the planes' image nodes, the quarter's B-spline
//! stencils reached free nodes past the planes and the body did not keep to them.

mod common;

use common::final_world;
use fissure::base::dim::{D2, D3};
use fissure::base::sym::SymTensor;
use fissure::store::world::World;
use fissure::systems::DimSystems;
use std::collections::HashMap;

/// Half the body's width on x and y (m); the cells are 1 mm.
const HALF: f64 = 0.008;

/// The body in `dim` dimensions: the quarter x, y >= 0 held by planes x = 0 and y = 0
/// (`quarter`), else the whole body from -HALF to HALF; 6 mm deep on z in 3D. A force
/// pulls the particles near each corner outward and sideways (the quarter's corner alone,
/// the whole body's four reflected, the 3D ones on the upper half of the depth only).
/// `simulation` adds keys to `[simulation]`.
fn scene(dim: usize, quarter: bool, simulation: &str) -> String {
    let lo = if quarter { 0.0 } else { -HALF };
    let xyz = |x: f64, y: f64, zv: f64| {
        if dim == 3 {
            format!("[{x:e}, {y:e}, {zv:e}]")
        } else {
            format!("[{x:e}, {y:e}]")
        }
    };
    let margin = 0.003;
    let mut text = format!(
        r#"name = "symmetry"
[simulation]
dimension = {dim}
shape = "bspline"
duration = 1e-4
{simulation}
[grid]
min = {gmin}
max = {gmax}
cell = {cell}
[[material]]
name = "m"
E = 1e9
nu = 0.3
rho = 1000.0
[[body]]
material = "m"
box = {{ min = {bmin}, max = {bmax} }}
"#,
        gmin = xyz(lo - margin, lo - margin, -margin),
        gmax = xyz(HALF + margin, HALF + margin, 0.006 + margin),
        cell = xyz(0.001, 0.001, 0.001),
        bmin = xyz(lo, lo, 0.0),
        bmax = xyz(HALF, HALF, 0.006),
    );
    let signs: &[(f64, f64)] = if quarter {
        &[(1.0, 1.0)]
    } else {
        &[(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
    };
    for &(sx, sy) in signs {
        let (a, b) = (0.005, HALF);
        let (x0, x1) = (f64::min(sx * a, sx * b), f64::max(sx * a, sx * b));
        let (y0, y1) = (f64::min(sy * a, sy * b), f64::max(sy * a, sy * b));
        text += &format!(
            "[[load]]\nregion = {{ min = {}, max = {} }}\nforce = {}\n",
            xyz(x0, y0, 0.003),
            xyz(x1, y1, 0.006),
            xyz(sx * 2.0e3, sy * 3.0e3, 0.0),
        );
    }
    if quarter {
        text += "[[boundary]]\nplane = { axis = \"x\", at = 0.0 }\n";
        text += "[[boundary]]\nplane = { axis = \"y\", at = 0.0 }\n";
    }
    text
}

/// The largest difference between each quarter particle's displacement, velocity and
/// stress and those of the whole body's particle that started where it did, each relative
/// to the largest value of its kind in the quarter (zero where both are zero).
fn largest_gaps<D: DimSystems>(quarter: &World<D>, whole: &World<D>, free_z: bool) -> [f64; 3] {
    let key = |x: D::Vec| {
        let x = D::to_xyz(x);
        x.map(|c| (c * 1e9).round() as i64)
    };
    let at: HashMap<[i64; 3], usize> = (whole.particles.x0.iter().enumerate())
        .map(|(j, &x)| (key(x), j))
        .collect();
    let (q, w) = (&quarter.particles, &whole.particles);
    let norm = |v: D::Vec| D::dot(v, v).sqrt();
    let stress = |s: &D::Sym| s.to_sym3();
    // The mean displacement along z, a rigid motion both bodies are free to make.
    let mean_z = |p: &fissure::store::particles::Particles<D>| {
        let mut m = D::zero();
        if free_z {
            m[2] = (0..p.len()).map(|i| p.x[i][2] - p.x0[i][2]).sum::<f64>() / p.len() as f64;
        }
        m
    };
    let (qz, wz) = (mean_z(q), mean_z(w));
    let (mut gaps, mut scale) = ([0.0f64; 3], [0.0f64; 3]);
    for i in 0..q.len() {
        let j = at[&key(q.x0[i])];
        let (du, dw) = (q.x[i] - q.x0[i] - qz, w.x[j] - w.x0[j] - wz);
        gaps[0] = gaps[0].max(norm(du - dw));
        scale[0] = scale[0].max(norm(du));
        gaps[1] = gaps[1].max(norm(q.v[i] - w.v[j]));
        scale[1] = scale[1].max(norm(q.v[i]));
        let (a, b) = (stress(&q.stress[i]), stress(&w.stress[j]));
        let diff = [
            a.xx - b.xx,
            a.yy - b.yy,
            a.zz - b.zz,
            a.xy - b.xy,
            a.yz - b.yz,
            a.xz - b.xz,
        ];
        gaps[2] = gaps[2].max(diff.iter().fold(0.0f64, |m, d| m.max(d.abs())));
        scale[2] = scale[2].max(
            [a.xx, a.yy, a.xy]
                .iter()
                .fold(0.0f64, |m, d| m.max(d.abs())),
        );
    }
    assert!(
        scale[0] > 0.0 && scale[2] > 0.0,
        "the quarter did not move: {scale:?}"
    );
    // A static run's velocities are zero in both.
    [0, 1, 2].map(|k| {
        if gaps[k] == 0.0 {
            0.0
        } else {
            gaps[k] / scale[k]
        }
    })
}

/// Explicit, 200 steps of the default update: the quarter's particles keep to the whole
/// body's to 1e-9 of the largest displacement, velocity and stress (round-off from the
/// grids' different origins grows over the steps; a free node past a plane gives percents).
#[test]
fn a_quarter_on_two_b_spline_symmetry_planes_moves_as_the_whole_body() {
    fn check<D: DimSystems>(dim: usize) {
        let quarter = final_world::<D>(&scene(dim, true, ""), 2);
        let whole = final_world::<D>(&scene(dim, false, ""), 2);
        let gaps = largest_gaps(&quarter, &whole, false);
        assert!(gaps.iter().all(|&g| g < 1e-9), "{dim}D: {gaps:?}");
    }
    check::<D2>(2);
    check::<D3>(3);
}

/// Static, one load step solved to 1e-12: the quarter's displacements and stresses are the
/// whole body's to 1e-8 of their largest (the solves' tolerance, through the stiffness's
/// conditioning). Both bodies are free to move along z in 3D, and each solve takes out its
/// own grid's mean of that motion: the particles' mean z displacement is compared apart.
#[test]
fn a_static_quarter_on_two_b_spline_symmetry_planes_is_the_whole_body() {
    fn check<D: DimSystems>(dim: usize) {
        let sim = "solver = \"static\"\nload_steps = 1\ntolerance = 1e-12";
        let quarter = final_world::<D>(&scene(dim, true, sim), 2);
        let whole = final_world::<D>(&scene(dim, false, sim), 2);
        let [u, _, s] = largest_gaps(&quarter, &whole, dim == 3);
        assert!(
            u < 1e-8 && s < 1e-8,
            "{dim}D: displacement {u:e}, stress {s:e}"
        );
    }
    check::<D2>(2);
    check::<D3>(3);
}

/// A crack that reaches a B-spline symmetry plane's image nodes stops the run at its first
/// step with a message naming the plane: the images stand for one field of their source,
/// and the crack's mirror half is not modelled.
#[test]
fn a_crack_at_a_b_spline_symmetry_plane_stops_with_a_message() {
    let crack = "[[crack]]\nline = { start = [0.0, 0.0045], end = [0.003, 0.0045] }\n";
    let text = scene(2, true, "") + crack;
    let src = common::source(&text);
    let options = fissure::app::run::RunOptions::default();
    match fissure::app::run::run(&src, &options) {
        Ok(_) => panic!("a crack at a B-spline symmetry plane must stop the run"),
        Err(e) => {
            let msg = format!("{e:#}");
            assert!(msg.contains("symmetry plane"), "{msg}");
        }
    }
}

/// The particles' momentum on `axis` (kg m/s): the quarter's mass times velocity.
fn momentum<D: DimSystems>(world: &World<D>, axis: usize) -> f64 {
    let p = &world.particles;
    (0..p.len()).map(|i| p.mass[i] * p.v[i][axis]).sum()
}

/// What the quarter's loads and gravity pull with on `axis` (N): the corner load's force
/// and the particles' weight.
fn applied<D: DimSystems>(world: &World<D>, axis: usize) -> f64 {
    let load = [2.0e3, 3.0e3][axis];
    let weight: f64 = world.particles.mass.iter().sum::<f64>() * world.settings.gravity[axis];
    load + weight
}

/// The reaction the plane `boundary` (0: x = 0, 1: y = 0) exerts on its normal `boundary`.
fn plane_reaction<D: DimSystems>(world: &World<D>, boundary: usize) -> f64 {
    world.bcs[boundary]
        .reaction
        .iter()
        .map(|r| r[boundary])
        .sum()
}

/// Gravity with a component across each plane (the mirror halves feel it reflected).
fn gravity(dim: usize) -> String {
    let g = if dim == 3 {
        "[-40.0, 60.0, 0.0]"
    } else {
        "[-40.0, 60.0]"
    };
    format!("gravity = {g}\n")
}

/// Static, solved to 1e-12: each plane's reaction on its normal balances the quarter's load
/// and weight along it (the equilibrium of the quarter, to the solve's tolerance), after
/// one load step (the solve's reactions) and after a second under the same load (which
/// solves nothing and reads them from the stresses). The plane's own nodes carry only part
/// of it on B-splines: without the images' part the balance is a quarter off.
#[test]
fn a_static_b_spline_symmetry_plane_reacts_with_the_force_across_it() {
    fn check<D: DimSystems>(dim: usize, steps: usize) {
        let sim = format!("solver = \"static\"\nload_steps = {steps}\ntolerance = 1e-12\n");
        let text = scene(dim, true, &(sim + &gravity(dim)));
        let quarter = final_world::<D>(&text, 2);
        let without = common::final_world_with::<D>(&text, 2, |w| w.grid.mirrors.credits.clear());
        for axis in 0..2 {
            let f = applied(&quarter, axis);
            let gap = (plane_reaction(&quarter, axis) + f).abs() / f.abs();
            assert!(gap < 1e-8, "{dim}D, {steps} steps, plane {axis}: {gap:e}");
            let off = (plane_reaction(&without, axis) + f).abs() / f.abs();
            assert!(
                off > 0.1,
                "{dim}D, plane {axis} without the images: {off:e}"
            );
        }
    }
    for steps in [1, 2] {
        check::<D2>(2, steps);
        check::<D3>(3, steps);
    }
}

/// The largest gap, over the two planes' normals, between the change of the quarter's
/// momentum over its 60th explicit step and dt times its load, weight and plane reaction,
/// relative to dt times the load and weight; `credited`: with the images' part of the
/// reactions.
fn momentum_gap<D: DimSystems>(dim: usize, credited: bool) -> f64 {
    let src = common::source(&scene(dim, true, &gravity(dim)));
    let scene = fissure::io::scenario::build::<D>(&src).unwrap_or_else(|e| panic!("{e}"));
    let mut world = scene.world;
    if !credited {
        world.grid.mirrors.credits.clear();
    }
    let mut schedule = fissure::pipeline::schedule::Schedule::for_world(&world, None);
    for _ in 0..59 {
        schedule.step(&mut world).unwrap();
    }
    let before = [0, 1].map(|a| momentum(&world, a));
    schedule.step(&mut world).unwrap();
    let dt = world.settings.dt;
    (0..2)
        .map(|axis| {
            let change = momentum(&world, axis) - before[axis];
            let balance = dt * (applied(&world, axis) + plane_reaction(&world, axis));
            (change - balance).abs() / (dt * applied(&world, axis)).abs()
        })
        .fold(0.0, f64::max)
}

/// Explicit, undamped: over one step the quarter's momentum on each plane's normal changes
/// by dt times its load, its weight and the plane's reaction (the FLIP update moves each
/// particle by the nodes' accelerations, so the balance is exact to round-off), checked at
/// the 60th step while waves still cross the body. Without the images' part of the
/// reactions the balance is 5 to 26 % off.
#[test]
fn an_explicit_b_spline_symmetry_plane_reacts_with_the_force_across_it() {
    for (dim, gap, off) in [
        (2, momentum_gap::<D2>(2, true), momentum_gap::<D2>(2, false)),
        (3, momentum_gap::<D3>(3, true), momentum_gap::<D3>(3, false)),
    ] {
        assert!(gap < 1e-10, "{dim}D: {gap:e}");
        assert!(off > 0.01, "{dim}D without the images: {off:e}");
    }
}
