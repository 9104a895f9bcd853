//! Explicit cracks: a crack through a bar decouples the halves exactly; crack vertices and
//! surfaces move with their fields; a scene without cracks schedules no crack system.

mod common;
use common::{final_world, source};
use fissure::app::run::{RunOptions, run};
use fissure::base::dim::D2;
use fissure::fracture::plan::TipResult;
use fissure::io::scenario::Source;
use fissure::io::scenario::build;
use fissure::pipeline::schedule::Schedule;

/// A 32 x 4 mm bar of 1 mm cells whose left half moves at -1 m/s and right half at +1 m/s,
/// with `crack` appended (may be empty).
fn pulled_apart(shape: &str, update: &str, crack: &str) -> String {
    common::strip_2d(
        &format!("shape = \"{shape}\"\nupdate = \"{update}\""),
        2e-5,
        &format!(
            r#"[[body]]
material = "m"
box = {{ min = [0.004, 0.004], max = [0.02, 0.008] }}
velocity = [-1.0, 0.0]
[[body]]
material = "m"
box = {{ min = [0.02, 0.004], max = [0.036, 0.008] }}
velocity = [1.0, 0.0]
{crack}
"#
        ),
    )
}

/// A crack along the grid line x = 20 mm (nodes on the crack line), through the section.
const ON_GRID_LINE: &str = "[[crack]]\npoints = [[0.02, 0.0025], [0.02, 0.0095]]\ntips = []";

/// The bar's kinetic and strain energy (J) and total momentum x (kg m/s) at the end.
fn energies(text: &str, threads: usize) -> (f64, f64, f64, fissure::store::world::World<D2>) {
    let w = final_world::<D2>(text, threads);
    let e = w.energies();
    let p = w.momentum();
    (e.kinetic, e.strain, p.x, w)
}

/// With the crack the halves fly apart unstressed: no strain energy, kinetic energy and
/// every particle velocity unchanged. Without it the same scene stretches the bar.
#[test]
fn a_crack_through_a_bar_lets_the_halves_separate_freely() {
    for (shape, update) in [("ugimp", "usavg"), ("linear", "usl"), ("bspline", "usf")] {
        let (k0, s0, _, _) = energies(&pulled_apart(shape, update, ""), 1);
        assert!(
            s0 > 1e-3 * k0,
            "{shape}: without a crack the bar is stretched"
        );

        let text = pulled_apart(shape, update, ON_GRID_LINE);
        let (k, s, px, w) = energies(&text, 1);
        let mass: f64 = w.particles.mass.iter().sum();
        let k_exact = 0.5 * mass * 1.0;
        assert!(
            s < 1e-20 * k,
            "{shape}: strain energy {s:e} J with the crack"
        );
        assert!(
            (k - k_exact).abs() < 1e-12 * k_exact,
            "{shape}: {k} vs {k_exact}"
        );
        assert!(px.abs() < 1e-12 * mass, "{shape}: momentum {px:e}");
        for (x, v) in w.particles.x.iter().zip(&w.particles.v) {
            let want = if x.x < 0.02 { -1.0 } else { 1.0 };
            assert!(
                (v.x - want).abs() < 1e-12 && v.y.abs() < 1e-12,
                "{shape}: {v}"
            );
        }
    }
}

/// A crack between grid lines and inclined to them decouples the halves as well.
#[test]
fn an_inclined_crack_off_the_grid_lines_decouples_too() {
    let crack = "[[crack]]\npoints = [[0.0197, 0.0025], [0.0203, 0.0095]]\ntips = []";
    let text = pulled_apart("ugimp", "usavg", crack)
        .replace("max = [0.02, 0.008]", "max = [0.0196, 0.008]")
        .replace("min = [0.02, 0.004]", "min = [0.0204, 0.004]");
    let (k, s, _, _) = energies(&text, 1);
    assert!(s < 1e-20 * k, "strain energy {s:e} J with the crack");
}

/// The crack plane moves with the centre-of-mass field (here at rest), the top surface
/// (left of the crack's direction) with the left half and the bottom with the right half,
/// so the opening at mid-height is 2 v t.
#[test]
fn crack_surfaces_follow_their_fields() {
    let line = "[[crack]]\nline = { start = [0.02, 0.0025], end = [0.02, 0.0095], spacing = 5e-4 }\ntips = []";
    let text = pulled_apart("ugimp", "usavg", line);
    let w = final_world::<D2>(&text, 2);
    let c = w.cracks.as_ref().expect("the scene has a crack");
    let t = w.time;
    let k = c
        .geometry
        .x
        .iter()
        .position(|x| (x.y - 0.006).abs() < 1e-12)
        .expect("a vertex at mid-height");
    assert!(
        (c.geometry.x[k].x - 0.02).abs() < 1e-15,
        "plane {}",
        c.geometry.x[k]
    );
    assert!(
        (c.geometry.top[k].x - (0.02 - t)).abs() < 1e-12 * 0.02,
        "top {}",
        c.geometry.top[k]
    );
    assert!(
        (c.geometry.bottom[k].x - (0.02 + t)).abs() < 1e-12 * 0.02,
        "bottom {}",
        c.geometry.bottom[k]
    );
}

/// Crack systems are scheduled only when the scene has a crack.
#[test]
fn crack_systems_only_in_scenes_with_cracks() {
    let names = |text: &str| -> Vec<&'static str> {
        let w = build::<D2>(&source(text)).unwrap().world;
        Schedule::for_world(&w, None)
            .systems
            .iter()
            .map(|s| s.name())
            .collect()
    };
    let plain = names(&pulled_apart("ugimp", "usavg", ""));
    assert!(!plain.contains(&"classify") && !plain.contains(&"crack_advect"));
    let cracked = names(&pulled_apart("ugimp", "usavg", ON_GRID_LINE));
    assert_eq!(
        cracked,
        [
            "bin",
            "classify",
            "p2g",
            "stress_force",
            "grid_update",
            "g2p_remap",
            "crack_advect",
            "stress_bin"
        ]
    );
}

/// With a crack, the closing stress update fused with the binning gives the bits of the
/// two systems run apart (the particles near the crack are updated first, from the
/// stencils their fields were classified with).
#[test]
fn fused_closing_stress_matches_unfused_with_a_crack() {
    let text = pulled_apart("ugimp", "usavg", ON_GRID_LINE)
        .replace("velocity = [1.0, 0.0]", "velocity = [0.3, 0.2]");
    let (fused, apart) = common::fused_and_unfused::<D2>(&text, 40);
    let bits = |w: &fissure::store::world::World<D2>| {
        format!(
            "{:?} {:?} {:?}",
            w.particles.stress, w.particles.x, w.particles.v
        )
    };
    assert!(bits(&fused) == bits(&apart));
}

/// Results with a crack are bitwise identical for 1 and 2 threads.
#[test]
fn cracked_scene_is_deterministic_across_threads() {
    let text = pulled_apart("ugimp", "usavg", ON_GRID_LINE)
        .replace("velocity = [1.0, 0.0]", "velocity = [0.3, 0.2]");
    let bits = |w: &fissure::store::world::World<D2>| -> Vec<u64> {
        let p = &w.particles;
        p.x.iter()
            .chain(&p.v)
            .flat_map(|v| [v.x.to_bits(), v.y.to_bits()])
            .chain(p.stress.iter().map(|s| s.xx.to_bits()))
            .collect()
    };
    assert!(bits(&final_world::<D2>(&text, 1)) == bits(&final_world::<D2>(&text, 2)));
}

/// Two cracks one cell apart cut the bar into three pieces moving at -1, 0 and +1 m/s:
/// nodes between them see both cracks and carry a field per crack side; every piece keeps
/// its velocity and nothing is strained.
#[test]
fn two_close_cracks_cut_three_free_pieces() {
    let text = common::strip_2d(
        "",
        2e-5,
        r#"[[body]]
material = "m"
box = { min = [0.004, 0.004], max = [0.0195, 0.008] }
velocity = [-1.0, 0.0]
[[body]]
material = "m"
box = { min = [0.0195, 0.004], max = [0.0205, 0.008] }
velocity = [0.0, 0.0]
[[body]]
material = "m"
box = { min = [0.0205, 0.004], max = [0.036, 0.008] }
velocity = [1.0, 0.0]
[[crack]]
points = [[0.0195, 0.0025], [0.0195, 0.0095]]
tips = []
[[crack]]
points = [[0.0205, 0.0025], [0.0205, 0.0095]]
tips = []
"#,
    );
    let w = final_world::<D2>(&text, 2);
    assert_free_pieces(&w, |x| {
        if x < 0.0195 {
            -1.0
        } else if x < 0.0205 {
            0.0
        } else {
            1.0
        }
    });
    let f = &w.cracks.as_ref().unwrap().scratch.fields;
    assert!(
        f.mask.iter().any(|m| m.count_ones() == 1 && m >> 2 != 0)
            && f.mask.iter().any(|m| m & 3 != 0),
        "fields of both cracks"
    );
    let nodes_with_both = f
        .node
        .iter()
        .filter(|&&n| {
            let rows = f.rows_of(n);
            let m: u64 = f.mask[rows.start - f.nodes..rows.end - f.nodes]
                .iter()
                .fold(0, |a, b| a | b);
            m & 3 != 0 && m >> 2 != 0
        })
        .count();
    assert!(
        nodes_with_both > 0,
        "some nodes carry fields of both cracks"
    );
}

/// Pieces cut by cracks fly apart freely: no strain energy (below 1e-20 of the kinetic),
/// and every particle keeps the velocity along x that `want` gives at its position, and
/// none along y, to 1e-12 m/s.
fn assert_free_pieces(w: &fissure::store::world::World<D2>, want: impl Fn(f64) -> f64) {
    let e = w.energies();
    assert!(
        e.strain < 1e-20 * e.kinetic,
        "strain energy {:e} J",
        e.strain
    );
    for (x, v) in w.particles.x.iter().zip(&w.particles.v) {
        let want = want(x.x);
        assert!(
            (v.x - want).abs() < 1e-12 && v.y.abs() < 1e-12,
            "at {x}: {v}, want {want}"
        );
    }
}

/// Steps `text` to the end on one thread, classifying every particle afresh every step when
/// `every_step`, else reusing what still holds.
fn stepped(text: &str, every_step: bool) -> fissure::store::world::World<D2> {
    common::final_world_with::<D2>(text, 1, |w| {
        w.cracks.as_mut().unwrap().scratch.classified.every_step = every_step;
    })
}

/// The classification record is reused only while nothing can have changed a crossing, so
/// the results are bitwise those of classifying afresh every step: here the right half
/// deforms and sweeps an inclined interior crack most of a cell across the grid (full
/// passes, particles changing stencils, and lattice lines through crack vertices).
#[test]
fn reusing_the_classification_changes_no_bit() {
    reused_classification_matches_fresh("crossing");
}

/// The same with `split = "inside"`, whose feet may cross the crack's edge with any motion.
#[test]
fn reusing_the_inside_classification_changes_no_bit() {
    reused_classification_matches_fresh("inside");
}

fn reused_classification_matches_fresh(split: &str) {
    let text = pulled_apart(
        "ugimp",
        "usavg",
        &format!(
            "[[crack]]\nline = {{ start = [0.024, 0.0052], end = [0.03, 0.0071], spacing = \
             5.0e-4 }}\ntips = [\"start\", \"end\"]\nsplit = \"{split}\""
        ),
    )
    .replace("2e-5", "1.2e-4")
    .replace("velocity = [1.0, 0.0]", "velocity = [15.0, 4.0]");
    let bits = |w: &fissure::store::world::World<D2>| -> Vec<u64> {
        let p = &w.particles;
        p.x.iter()
            .chain(&p.v)
            .chain(&w.cracks.as_ref().unwrap().geometry.x)
            .flat_map(|v| [v.x.to_bits(), v.y.to_bits()])
            .chain(p.stress.iter().map(|s| s.xy.to_bits()))
            .collect()
    };
    let fresh = stepped(&text, true);
    let reused = stepped(&text, false);
    let c = reused.cracks.as_ref().unwrap();
    let start = build::<D2>(&source(&text))
        .unwrap()
        .world
        .cracks
        .unwrap()
        .geometry
        .x[0];
    assert!(
        (c.geometry.x[0] - start).length() > 5e-4,
        "the crack moved {:e} m",
        (c.geometry.x[0] - start).length()
    );
    assert!(
        c.scratch.classified.drift > 0.0,
        "the last step reused the record"
    );
    assert!(bits(&fresh) == bits(&reused));
}

/// J read after a step that keeps its stencils equals J after the same steps run with the
/// closing stress update unfused; after a fused step it does not (the fused update re-bins,
/// and J would read the new stencils against the step's crack fields).
#[test]
fn j_after_a_kept_step_matches_the_unfused_schedule() {
    let text = std::fs::read_to_string("scenarios/dcb_2d.toml").unwrap();
    let scene = build::<D2>(&source(&text)).unwrap();
    let plan = scene.fracture.clone().unwrap();
    let mut kept = scene.world;
    let (mut apart, mut fused) = (kept.clone(), kept.clone());
    let mut schedule = Schedule::for_world(&kept, None);
    let (mut unfused, mut fused_schedule) = (schedule.clone(), schedule.clone());
    // By step 300 the load's wave has reached the tip (J far above round-off).
    for k in 0..300 {
        schedule.step_keeping(&mut kept, k == 299).unwrap();
        unfused.step_keeping(&mut apart, true).unwrap();
        fused_schedule.step(&mut fused).unwrap();
    }
    let j = |w: &fissure::store::world::World<D2>| {
        format!("{:?}", fissure::systems::fracture::measure(w, &plan).tips)
    };
    assert_eq!(j(&kept), j(&apart));
    assert_ne!(j(&fused), j(&apart));
}

/// `[fracture] lengths = "m"`: the contours, tube and domain stay where they are when the
/// grid is refined (whole cells for the contours), so a refinement study converges
/// instead of shrinking them; a fraction of a cell in cells, or an unknown unit, is
/// refused.
#[test]
fn fracture_sizes_in_metres_follow_the_grid() {
    let plate = |fracture: &str, cell: f64| {
        common::edge_plate("", 1e-6)
            .replace("[crack.growth]\n\n", "")
            .replace("contour = 2\n", fracture)
            .replace(
                "cell = [0.0005, 0.0005]",
                &format!("cell = [{cell:e}, {cell:e}]"),
            )
            .replace("start = [-0.0005, 0.0]", "start = [-0.0004, 0.0]")
    };
    let metres = "lengths = \"m\"\ncontour = 1.0e-3\ncompare = [2.0e-3]\ndomain = 3.0e-3\n";
    for (cell, n) in [(5e-4, 2), (2.5e-4, 4)] {
        let src = common::source(&plate(metres, cell));
        let plan = fissure::io::scenario::build::<D2>(&src)
            .unwrap()
            .fracture
            .unwrap();
        assert_eq!(
            (plan.contour, plan.compare.clone()),
            (n, vec![2 * n]),
            "cell {cell}"
        );
        assert!(
            (plan.domain - 3.0 * n as f64).abs() < 1e-9,
            "{}",
            plan.domain
        );
    }
    for (fracture, words) in [
        ("contour = 1.5\n", "whole number of cells"),
        ("lengths = \"mm\"\n", "unknown unit"),
    ] {
        let src = common::source(&plate(fracture, 5e-4));
        let Err(e) = fissure::io::scenario::build::<D2>(&src) else {
            panic!("`{fracture}` must be refused");
        };
        assert!(e.to_string().contains(words), "{e}");
    }
}

/// An edge crack along the middle of a steel strip 8 mm thick between aluminium layers
/// (60 x 41 mm, plane strain, 1 mm cells), pulled by its ends and damped to rest.
fn sandwich() -> String {
    r#"[simulation]
dimension = 2
plane = "strain"
duration = 3.0e-4
damping = 1.5e5
[grid]
min = [-0.003, -0.003]
max = [0.063, 0.043]
cell = [0.001, 0.001]
anchor = { point = [0.0, 0.0205], offset = [0.0, 0.5] }
[[material]]
name = "al"
E = 70e9
nu = 0.33
rho = 2700.0
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "al"
box = { min = [0.0, 0.0], max = [0.06, 0.0165] }
[[body]]
material = "steel"
box = { min = [0.0, 0.0165], max = [0.06, 0.0245] }
[[body]]
material = "al"
box = { min = [0.0, 0.0245], max = [0.06, 0.041] }
[[crack]]
name = "c"
line = { start = [-0.002, 0.0205], end = [0.02, 0.0205], spacing = 5.0e-4 }
[[load]]
region = { min = [0.0, 0.0405], max = [0.06, 0.041] }
force = [0.0, 1500.0]
time = { kind = "ramp", rise = 5.0e-5 }
[[load]]
region = { min = [0.0, 0.0], max = [0.06, 0.0005] }
force = [0.0, -1500.0]
time = { kind = "ramp", rise = 5.0e-5 }
[fracture]
contour = 3
compare = [2]
[output]
history_interval = 1.0e-4
"#
    .to_string()
}

/// The sandwich is in mode I by symmetry, and nothing varies along its crack, so J is the
/// same on every contour (Rice 1968) and K_I = sqrt(E' J) with the steel's E' on a contour
/// inside the steel (2 cells). The interaction integral's auxiliary field is that of a
/// homogeneous body, so its domain (6 cells asked) must shrink to stay in the steel: there
/// it reads K_I within 1 % of sqrt(E' J) (0.4 %; 1.9 % high with the domain across the
/// interfaces; at 0.25 mm cells both read 22.7 MPa sqrt(m), 0.4 % below this contour's).
/// The reported K is the interaction integral's ratio at the lower G of it and J.
#[test]
fn interaction_domain_stays_in_the_tips_material() {
    let h = common::history(&sandwich());
    let tip = *h.fracture.last().expect("a tip row");
    assert!(
        tip.domain > 0.0 && tip.domain <= 4e-3,
        "domain {} m reaches the aluminium 4 mm away",
        tip.domain
    );
    let inner = h.paths.iter().rfind(|p| p.contour == 2).expect("contour 2");
    let j = inner.line[0] + inner.area[0];
    let e_prime = 200e9 / (1.0 - 0.3 * 0.3);
    let k_j = (e_prime * j).sqrt();
    let err = tip.k_interaction[0] / k_j - 1.0;
    assert!(
        err.abs() < 0.01,
        "K_I {} vs sqrt(E'J) {k_j}: {err:+.4}",
        tip.k_interaction[0]
    );
    assert!(
        tip.k_interaction[1].abs() < 0.01 * k_j,
        "K_II {}",
        tip.k_interaction[1]
    );
    // The default K (`lower_g`): the interaction integral's ratio at the lower of its G and
    // the main contour's J (the tip points along +x, so G = J1), with the tip's E'.
    let norm = |k: [f64; 3]| k[0].hypot(k[1]);
    let lower = norm(tip.k_interaction).min((e_prime * tip.j[0]).sqrt());
    assert!(
        (norm(tip.k) / lower - 1.0).abs() < 1e-12,
        "reported {:?}, lower |K| {lower}",
        tip.k
    );
    let ratio = |k: [f64; 3]| k[1] / k[0];
    assert!((ratio(tip.k) - ratio(tip.k_interaction)).abs() < 1e-12);
}

/// More cracks than a field's mask has colours: a 92 mm bar cut by 91 cracks into 92
/// pieces 1 mm wide (uGIMP), each moving along the bar faster than the one to its left.
/// The cracks take 8 colours (those within 3.5 cells of one another differ), and every
/// piece flies off on its own: no strain energy and every velocity unchanged, as with two
/// cracks; one thread and two give the same positions to the bit.
#[test]
fn ninety_one_cracks_cut_ninety_two_free_pieces() {
    let mut text = String::from(
        "[simulation]\ndimension = 2\nshape = \"ugimp\"\nduration = 2e-5\n[grid]\n\
         min = [0.0, 0.0]\nmax = [0.1, 0.012]\ncell = [0.001, 0.001]\n[[material]]\n\
         name = \"m\"\nE = 70e9\nnu = 0.3\nrho = 2700.0\n",
    );
    let edge = |k: usize| 0.0045 + 0.001 * k as f64;
    for k in 0..92 {
        text += &format!(
            "[[body]]\nmaterial = \"m\"\nbox = {{ min = [{:.4}, 0.004], max = [{:.4}, 0.008] }}\n\
             velocity = [{:.3}, 0.0]\n",
            edge(k),
            edge(k + 1),
            0.05 * k as f64
        );
    }
    for k in 1..92 {
        text += &format!(
            "[[crack]]\npoints = [[{x:.4}, 0.0025], [{x:.4}, 0.0095]]\ntips = []\n",
            x = edge(k)
        );
    }
    let w = final_world::<D2>(&text, 2);
    assert_free_pieces(&w, |x| 0.05 * ((x - 0.0045) / 0.001).floor());
    let one = final_world::<D2>(&text, 1);
    assert!(
        (w.particles.x.iter().zip(&one.particles.x)).all(|(a, b)| a.to_array() == b.to_array()),
        "one thread and two differ"
    );
    let colors = &w.cracks.as_ref().unwrap().scratch.colors;
    assert_eq!(colors.len(), 91);
    assert!(colors.iter().all(|&c| c < 8), "{colors:?}");
}

/// Cracks that come within reach of too many others while a run goes on stop it with a
/// message naming them: 40 cracks 1 mm apart build (each has at most 14 within reach),
/// then, moved to a fifth of their spacing, classification refuses them.
#[test]
fn cracks_crowding_together_stop_the_run() {
    let mut text = common::strip_2d(
        "",
        1e-6,
        "[[body]]\nmaterial = \"m\"\nbox = { min = [0.0, 0.002], max = [0.04, 0.010] }\n",
    )
    .replace("max = [0.04, 0.012]", "max = [0.05, 0.012]");
    for k in 0..40 {
        let x = 0.0005 + 0.001 * k as f64;
        text += &format!(
            "[[crack]]\nname = \"c{k}\"\npoints = [[{x:.4}, 0.0051], [{x:.4}, 0.0069]]\ntips = []\n"
        );
    }
    let mut world = build::<D2>(&source(&text))
        .expect("40 cracks 1 mm apart")
        .world;
    fissure::systems::bin::run(&mut world).expect("binned");
    fissure::systems::classify::run(&mut world).expect("room for 40 cracks 1 mm apart");
    let cracks = world.cracks.as_mut().unwrap();
    for x in cracks.geometry.x.iter_mut() {
        x.x = 0.02 + 0.2 * (x.x - 0.02);
    }
    let e = fissure::systems::classify::run(&mut world).expect_err("no room any more");
    assert!(
        e.what.contains("came within reach of 32 other cracks"),
        "{}",
        e.what
    );
}

/// The last fracture rows (both tips) of `centre_crack_2d` solved static with its crack's
/// half-length `a` (m) and the further settings `more`.
fn centre_crack_static(a: f64, more: &[String]) -> Vec<TipResult> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/centre_crack_2d.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let mut sets = vec![
        "simulation.solver=\"static\"".to_string(),
        "output.history_interval=3e-4".to_string(),
        format!("crack[0].line.start=[{:.7},0.06]", 0.02 - a),
        format!("crack[0].line.end=[{:.7},0.06]", 0.02 + a),
    ];
    sets.extend_from_slice(more);
    let src = Source::parse("centre_crack_2d.toml", &text, &sets).unwrap();
    let h = run(&src, &RunOptions::default()).unwrap().history;
    let last = h.fracture.last().unwrap().step;
    h.fracture.into_iter().filter(|t| t.step == last).collect()
}

/// Where a tip lies within the particle spacing changes which particle-node lines cross
/// the crack near it, and with them how long the discrete crack acts: on `centre_crack_2d`
/// (static, 1 mm cells, two particles a cell) with both tips moved through one spacing in
/// eighths, J reads G from -1.6 % to +6.6 % (a jump where a tip passes the crossing point of
/// a line), while the interaction integral reads K_I within -0.8 % and +1.5 % (docs/
/// validation.md). The default K (the interaction integral's ratio at the lower G of the
/// two) must hold wherever a user's tip falls: at four places across the spacing, on both
/// sides of the jump, K_I within the 2 % the 2D default aims at of Feddersen's K_I for that
/// half-length (Tada's form, scenarios/reference/README.md), and K_II within 0.1 % of it.
#[test]
fn default_k_holds_wherever_the_tip_lies_in_the_particle_spacing() {
    let e_mod = 200e9;
    let mut j_spread = (f64::INFINITY, f64::NEG_INFINITY);
    for eighths in [0, 2, 3, 5] {
        let a = 0.01 + 6.25e-5 * f64::from(eighths);
        let k_ref = common::feddersen(100e6, a, 0.02);
        for tip in centre_crack_static(a, &[]) {
            let err = tip.k[0] / k_ref - 1.0;
            assert!(err.abs() < 0.02, "a {a}: K_I {} ({err:+.4})", tip.k[0]);
            assert!(tip.k[1].abs() < 1e-3 * k_ref, "a {a}: K_II {}", tip.k[1]);
            let j = tip.j[0].hypot(tip.j[1]) / (k_ref * k_ref / e_mod) - 1.0;
            j_spread = (j_spread.0.min(j), j_spread.1.max(j));
        }
    }
    // The case is a hard one only if J's error does vary across the spacing.
    assert!(j_spread.1 - j_spread.0 > 0.04, "J from {j_spread:?}");
}

/// The crossing rule splits a particle-node pair whose line crosses the crack just behind
/// its tip, though the particle lies ahead of it, so the discrete crack acts longer than
/// drawn: on `centre_crack_2d` (static, 1 mm cells, two particles a cell) with both tips
/// moved through one particle spacing in eighths, J reads Feddersen's G (Tada's form,
/// scenarios/reference/README.md) +2.5 % high on average. `split = "inside"` splits a pair
/// only where both feet lie inside the crack, and the mean over the spacing comes within
/// 1 % of G (it reads +0.4 %; the sawtooth from -2.7 % to +4.3 % stays: the last split
/// pair still jumps as a tip passes a particle).
#[test]
fn inside_split_keeps_the_discrete_crack_as_long_as_drawn() {
    let mean_j_error = |split: &str| {
        let mut sum = 0.0;
        for eighths in 0..8 {
            let a = 0.01 + 6.25e-5 * f64::from(eighths);
            let k_ref = common::feddersen(100e6, a, 0.02);
            for tip in centre_crack_static(a, &[format!("crack[0].split=\"{split}\"")]) {
                sum += tip.j[0].hypot(tip.j[1]) / (k_ref * k_ref / 200e9) - 1.0;
            }
        }
        sum / 16.0
    };
    let crossing = mean_j_error("crossing");
    let inside = mean_j_error("inside");
    assert!(
        crossing > 0.02,
        "crossing: J / G - 1 = {crossing:+.4} on average"
    );
    assert!(
        inside.abs() < 0.01,
        "inside: J / G - 1 = {inside:+.4} on average"
    );
}
