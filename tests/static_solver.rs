//! The static solver (`solver = "static"`): equilibrium in one solve per load step. A 3D
//! column under its own weight against the closed form, its energy against the work of
//! gravity; the same bits on one and two threads; what it does not take yet refused by
//! name.

mod common;
use common::{final_world, history, source};
use fissure::base::dim::{D2, D3};
use fissure::io::scenario::build;

/// A steel column 10 x 10 x 100 mm (2 mm cells, 8 particles a cell) standing on rollers at
/// z = 0 under gravity g, `extra` appended.
fn column(extra: &str) -> String {
    format!(
        r#"
[simulation]
dimension = 3
duration = 1.0
solver = "static"
load_steps = 2
gravity = [0.0, 0.0, -9.81e4]
[grid]
min = [-0.004, -0.004, -0.004]
max = [0.014, 0.014, 0.104]
cell = [0.002, 0.002, 0.002]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 8000.0
[[body]]
material = "steel"
box = {{ min = [0.0, 0.0, 0.0], max = [0.01, 0.01, 0.1] }}
[[boundary]]
region = {{ min = [-0.004, -0.004, -0.004], max = [0.014, 0.014, 0.0] }}
fix = ["z"]
[[probe]]
name = "top"
region = {{ min = [0.0, 0.0, 0.099], max = [0.01, 0.01, 0.1] }}
quantity = "displacement"
component = "z"
[[probe]]
name = "floor"
region = {{ min = [-0.004, -0.004, -0.004], max = [0.014, 0.014, 0.0] }}
quantity = "reaction"
component = "z"
{extra}
"#
    )
}

/// Under a gravity of 10^4 g (so that the shortening is well above round-off) the top
/// particles (z = 99.5 mm) sink by rho g (L z - z^2 / 2) / E (a column free to contract
/// sideways), within 0.2 % (it reads 0.008 % at 50 cells along the column: uGIMP carries
/// the linearly varying stress almost exactly); the floor
/// carries the weight to 1e-6 (the solve stops at a residual of 1e-8 of the load); the
/// strain energy equals the work of gravity rising from zero (Clapeyron), to the same.
#[test]
fn column_under_its_own_weight() {
    let h = history(&column(""));
    let (rho, g, e, l, z) = (8000.0, 9.81e4, 200e9, 0.1, 0.0995);
    let want = -rho * g * (l * z - z * z / 2.0) / e;
    let top = *h.probes[0].last().unwrap();
    assert!((top - want).abs() / want.abs() < 2e-3, "{top} vs {want}");
    let weight = rho * g * 0.01 * 0.01 * l;
    let floor = *h.probes[1].last().unwrap();
    assert!(
        (floor - weight).abs() / weight < 1e-8,
        "{floor} vs {weight}"
    );
    let end = h.rows.last().unwrap().energies;
    assert!(end.strain > 0.0);
    assert!(
        (end.strain - end.external_work).abs() / end.strain < 1e-8,
        "{end:?}"
    );
}

/// Hill's plastic cylinder of scenarios/cylinder_plastic_2d.toml on 7.5 mm cells, solved
/// static with `extra` added to its `[simulation]` table.
fn coarse_cylinder(extra: &str) -> String {
    cylinder(extra).replace("cell = [0.0025, 0.0025]", "cell = [0.0075, 0.0075]")
}

/// The same cylinder on its shipped 2.5 mm cells (15,086 particles).
fn cylinder(extra: &str) -> String {
    let path = format!(
        "{}/scenarios/cylinder_plastic_2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&path).unwrap().replace(
        "[simulation]",
        &format!("[simulation]\nsolver = \"static\"\n{extra}"),
    )
}

/// The cantilever of scenarios/cantilever_static_2d.toml (solved directly, by conjugate
/// gradients and by conjugate gradients with the coarse grid, the last on B-splines too,
/// whose surface entries take blocks), the ENF specimen with its faces in contact and the plastic cylinder (with
/// each particle's dilatation and with its cell's mean), on one thread and on two: the same
/// bits in every particle's position and stress.
#[test]
fn static_solve_is_the_same_on_any_thread_count() {
    let read = |name: &str| {
        let path = format!("{}/scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        std::fs::read_to_string(path).unwrap()
    };
    let enf = read("enf_2d").replace(
        "[simulation]",
        "[simulation]\nsolver = \"static\"\nload_steps = 1",
    );
    let cylinder = coarse_cylinder("");
    let cg = read("cantilever_static_2d").replace(
        "solver = \"static\"",
        "solver = \"static\"\nlinear = \"cg\"",
    );
    let two_level = read("cantilever_static_2d").replace(
        "solver = \"static\"",
        "solver = \"static\"\nlinear = \"two_level\"",
    );
    let mean = coarse_cylinder("dilatation = \"cell_mean\"");
    let bspline = two_level.replace("shape = \"ugimp\"", "shape = \"bspline\"");
    for text in [
        read("cantilever_static_2d"),
        cg,
        bspline,
        two_level,
        enf,
        cylinder,
        mean,
    ] {
        let one = final_world::<D2>(&text, 1);
        let two = final_world::<D2>(&text, 2);
        assert!(one.particles.x != one.particles.x0, "the beam bent");
        assert_eq!(one.particles.x, two.particles.x);
        assert_eq!(
            format!("{:?}", one.particles.stress),
            format!("{:?}", two.particles.stress)
        );
    }
}

/// Stuck crack faces are refused in a static scene, naming the key (plasticity in 3D and
/// plane stress, and with frictionless faces, is taken); load steps, a
/// tolerance and a linear solver in an explicit scene too (the cell-mean dilatation is
/// taken there), that dilatation in plane stress, a tolerance outside 1e-12 to 1e-2 and a
/// linear solver that does not exist.
#[test]
fn what_the_static_solver_does_not_take_is_refused() {
    let err = |text: String| match build::<D3>(&source(&text)) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    let crack = "[[crack]]\nname = \"c\"\nrectangle = { center = [0.005, 0.005, 0.05], axes = \
         [[0.003, 0.0, 0.0], [0.0, 0.003, 0.0]] }";
    let e = err(column(&format!("{crack}\ncontact = {{ law = \"stick\" }}")));
    assert!(
        e.contains("crack[0].contact.law") && e.contains("stick"),
        "{e}"
    );
    let plastic = column("").replace(
        "rho = 8000.0",
        "rho = 8000.0\nmodel = \"j2\"\nsigma_y = 250e6",
    );
    assert_eq!(err(plastic.clone()), "", "3D plasticity is taken");
    let closing = format!("{plastic}\n{crack}\ncontact = {{ law = \"frictionless\" }}");
    assert_eq!(err(closing), "", "contact with plasticity is taken");
    let rubbing = format!("{plastic}\n{crack}\ncontact = {{ law = \"friction\", friction = 0.3 }}");
    assert_eq!(err(rubbing), "", "friction with plasticity is taken");
    let stress = common::strip_2d(
        "plane = \"stress\"\nsolver = \"static\"",
        3e-5,
        common::GRIPPED_BAR,
    )
    .replace(
        "rho = 2700.0",
        "rho = 2700.0\nmodel = \"j2\"\nsigma_y = 250e6",
    );
    let e = match build::<D2>(&source(&stress)) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    assert_eq!(e, "", "plane-stress plasticity is taken");
    let explicit = column("").replace("solver = \"static\"\n", "");
    let e = err(explicit);
    assert!(e.contains("simulation.load_steps"), "{e}");
    for (line, key) in [
        ("tolerance = 1e-6", "simulation.tolerance"),
        ("linear = \"direct\"", "simulation.linear"),
    ] {
        let explicit = column("")
            .replace("solver = \"static\"\n", "")
            .replace("load_steps = 2", line);
        let e = err(explicit);
        assert!(e.contains(key) && e.contains("static"), "{e}");
    }
    let mean = "load_steps = 2\ndilatation = \"cell_mean\"";
    assert_eq!(
        err(column("").replace("load_steps = 2", mean)),
        "",
        "3D static is taken"
    );
    let explicit = column("")
        .replace("solver = \"static\"\n", "")
        .replace("load_steps = 2", "dilatation = \"cell_mean\"");
    assert_eq!(err(explicit), "", "explicit is taken");
    let stress = common::strip_2d(
        "plane = \"stress\"\nsolver = \"static\"\ndilatation = \"cell_mean\"",
        3e-5,
        common::GRIPPED_BAR,
    );
    let e = match build::<D2>(&source(&stress)) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("simulation.dilatation") && e.contains("plane strain"),
        "{e}"
    );
    let unknown = column("").replace("load_steps = 2", "load_steps = 2\nlinear = \"lu\"");
    let e = match fissure::io::scenario::Source::parse("test.toml", &unknown, &[]) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("simulation.linear") && e.contains("`lu`"), "{e}");
    for t in ["1e-14", "0.5", "-1e-8"] {
        let e = err(column("").replace(
            "load_steps = 2",
            &format!("load_steps = 2\ntolerance = {t}"),
        ));
        assert!(
            e.contains("simulation.tolerance") && e.contains("between"),
            "{e}"
        );
    }
}

/// An aluminium bar 28 x 8 mm (plane stress, 10 mm thick) between two grips that hold x
/// only, the right one moved by a prescribed velocity of 0.1 m/s under a table that rises
/// over 10 us, holds 10 us and falls back over 10 us: 2 um in all by 30 us (the explicit
/// test of the same grips is in tests/loads.rs). Solved static in 12 load steps, the grip
/// pulls with E A d / L and the support holds with the opposite (uniaxial stress: y is free,
/// its rigid translation taken out) within 1e-6 (a uniform strain lies in the shape
/// functions' span, so only the solve's residual of 1e-8 is left; the explicit run reads
/// 1.1e-4 low, from integrating the rate of strain on the deforming bar); the strain energy
/// equals the grip's work (its force times its displacement, trapezoidal over each step:
/// exact for a linear response) to 1e-6 all along, and ends at E A d^2 / (2 L).
#[test]
fn a_moving_grip_prescribes_its_displacement() {
    let text = common::strip_2d(
        "plane = \"stress\"\nthickness = 0.01\nsolver = \"static\"\nload_steps = 12",
        3e-5,
        &format!(
            "{}\n[output]\nhistory_interval = 2.5e-6\n",
            common::GRIPPED_BAR
        ),
    );
    let h = history(&text);
    let (support, grip) = (*h.probes[0].last().unwrap(), *h.probes[1].last().unwrap());
    let tension = 70e9 * (0.008 * 0.01) * 2e-6 / 0.028;
    assert!(
        (grip - tension).abs() <= 1e-6 * tension,
        "{grip} vs {tension}"
    );
    assert!(
        (support + tension).abs() <= 1e-6 * tension,
        "{support} vs {tension}"
    );
    // While the grip speeds up, moves steadily and slows down: W = W_ext, and at the end
    // both are E A d^2 / (2 L).
    for t in [5e-6, 1e-5, 2e-5, 3e-5] {
        let row = h.rows.iter().find(|r| (r.time - t).abs() < 1e-12).unwrap();
        let e = row.energies;
        let gap = (e.strain - e.external_work).abs();
        assert!(e.strain > 0.0 && gap <= 1e-6 * e.strain, "{e:?}");
    }
    let end = h.rows.last().unwrap().energies.strain;
    let want = 0.5 * tension * 2e-6;
    assert!((end - want).abs() <= 1e-6 * want, "{end} vs {want}");
}

/// Keys that apply to explicit runs only (damping, cfl, an initial velocity) are ignored by
/// a static scene, and named: the column with them gives the same bits as without, and
/// its summary lists them.
#[test]
fn explicit_only_keys_are_ignored_by_name() {
    let plain = common::run_text(&column(""));
    let noisy = column("")
        .replace("load_steps = 2", "load_steps = 2\ndamping = 1e4\ncfl = 0.3")
        .replace(
            "material = \"steel\"\nbox",
            "material = \"steel\"\nvelocity = [0.0, 0.0, 5.0]\nbox",
        );
    let noisy = common::run_text(&noisy);
    assert_eq!(
        noisy.summary.ignored_keys,
        ["simulation.cfl", "simulation.damping", "body[0].velocity"]
    );
    assert!(plain.summary.ignored_keys.is_empty());
    let top = |o: &fissure::app::run::Outcome| o.history.probes[0].last().unwrap().to_bits();
    assert_eq!(top(&plain), top(&noisy));
}

/// `tolerance` is where each load step stops: the column at 1e-4 stops within it, in
/// fewer iterations than at the default 1e-8, and its floor still carries the weight
/// within 1e-3.
#[test]
fn the_tolerance_is_the_scenes() {
    let cg = |text: String| text.replace("load_steps = 2", "load_steps = 2\nlinear = \"cg\"");
    let exact = common::run_text(&cg(column("")));
    let loose = cg(column("")).replace("load_steps = 2", "load_steps = 2\ntolerance = 1e-4");
    let loose = common::run_text(&loose);
    let (a, b) = (
        exact.summary.static_solve.unwrap(),
        loose.summary.static_solve.unwrap(),
    );
    assert!(
        a.worst_residual <= 1e-8 && b.worst_residual <= 1e-4,
        "{a:?} {b:?}"
    );
    assert!(
        b.worst_residual > 1e-8 && b.iterations < a.iterations,
        "{a:?} {b:?}"
    );
    let weight = 8000.0 * 9.81e4 * 0.01 * 0.01 * 0.1;
    let floor = *loose.history.probes[1].last().unwrap();
    assert!(
        (floor - weight).abs() <= 1e-3 * weight,
        "{floor} vs {weight}"
    );
}

/// A column with nothing to stand on: gravity would start it moving, so equilibrium has no
/// solution, and the run stops saying so rather than returning a meaningless answer (a
/// free body under balanced loads, as `williams_2d`, solves: its rigid motions are taken
/// out).
#[test]
fn a_body_free_to_move_is_refused_by_the_solve() {
    let floating = column("")
        .replace("fix = [\"z\"]", "fix = [\"x\"]")
        .replace(
            "quantity = \"reaction\"\ncomponent = \"z\"",
            "quantity = \"reaction\"\ncomponent = \"x\"",
        );
    let opts = fissure::app::run::RunOptions::default();
    let e = match fissure::app::run::run(&source(&floating), &opts) {
        Ok(_) => String::new(),
        Err(e) => format!("{e:#}"),
    };
    assert!(
        e.contains("no static equilibrium") && e.contains("rigid motions"),
        "{e}"
    );
}

/// A shipped scene switched to static in one load step, as a user would (`--set`).
fn switched(name: &str) -> fissure::io::scenario::Source {
    switched_with(name, &[])
}

/// The text of the shipped scenario `scenarios/{name}.toml`.
fn shipped(name: &str) -> String {
    let path = format!("{}/scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap()
}

/// As [`switched`], with more `--set` overrides.
fn switched_with(name: &str, more: &[&str]) -> fissure::io::scenario::Source {
    let path = format!("{}/scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    let mut set = vec![
        "simulation.solver=\"static\"".to_string(),
        "simulation.load_steps=1".to_string(),
    ];
    set.extend(more.iter().map(|s| s.to_string()));
    fissure::io::scenario::Source::parse(&path, &text, &set).unwrap()
}

/// The same equilibrium by the two linear solvers: the sparse Cholesky factorization and
/// conjugate gradients (stopped at 1e-8 of the load) give every tip's K to 1e-6 (they agree
/// to 1e-9), on a free body under balanced tractions (williams_2d: three rigid motions,
/// pinned by the direct solve and taken out), a body on pins (ct_2d) and faces in contact
/// (enf_2d: frictionless ties along the crack's normal); the direct solve's residual is
/// round-off's (below 1e-10 of the load).
#[test]
fn direct_and_iterative_solves_agree() {
    let opts = fissure::app::run::RunOptions::default();
    for name in ["williams_2d", "ct_2d", "enf_2d"] {
        let direct = fissure::app::run::run(
            &switched_with(name, &["simulation.linear=\"direct\""]),
            &opts,
        )
        .unwrap();
        let cg = fissure::app::run::run(&switched_with(name, &["simulation.linear=\"cg\""]), &opts)
            .unwrap();
        let (d, c) = (
            direct.summary.static_solve.unwrap(),
            cg.summary.static_solve.unwrap(),
        );
        assert!(d.factorizations > 0 && d.iterations == 0, "{d:?}");
        assert!(c.factorizations == 0 && c.iterations > 0, "{c:?}");
        assert!(d.worst_residual < 1e-10, "{name}: {d:?}");
        same_last_k(name, &direct, &cg);
    }
}

/// Asserts that two runs' last fracture rows give K_I and K_II within 1e-6 of the first's
/// magnitude.
fn same_last_k(name: &str, a: &fissure::app::run::Outcome, b: &fissure::app::run::Outcome) {
    let k = |o: &fissure::app::run::Outcome| {
        let t = o.history.fracture.last().unwrap();
        (t.k[0], t.k[1])
    };
    let ((a1, a2), (b1, b2)) = (k(a), k(b));
    let scale = a1.hypot(a2);
    assert!(
        (a1 - b1).abs() <= 1e-6 * scale && (a2 - b2).abs() <= 1e-6 * scale,
        "{name}: ({a1}, {a2}) vs ({b1}, {b2})"
    );
}

/// Conjugate gradients with the coarse grid under Jacobi (`linear = "two_level"`) reach
/// the equilibrium of Jacobi alone: every tip's K within 1e-6 (both stop at 1e-8 of the
/// load) on a free body (williams_2d: the coarse stiffness keeps its rigid motions, which
/// the solve takes out), a body on pins (ct_2d) and faces in contact (enf_2d), in fewer
/// iterations (the coarse grid takes the long waves of the error that Jacobi leaves).
#[test]
fn the_coarse_grid_changes_the_iterations_not_the_answer() {
    let opts = fissure::app::run::RunOptions::default();
    for name in ["williams_2d", "ct_2d", "enf_2d"] {
        let solve = |linear: &str| {
            let set = format!("simulation.linear=\"{linear}\"");
            fissure::app::run::run(&switched_with(name, &[&set]), &opts).unwrap()
        };
        let (jacobi, coarse) = (solve("cg"), solve("two_level"));
        let iterations =
            |o: &fissure::app::run::Outcome| o.summary.static_solve.as_ref().unwrap().iterations;
        let (j, c) = (iterations(&jacobi), iterations(&coarse));
        assert!(
            c > 0 && c < j,
            "{name}: {c} iterations against Jacobi's {j}"
        );
        same_last_k(name, &jacobi, &coarse);
    }
}

/// A 6 mm steel cube on quadratic B-splines (0.5 mm cells, 2 mm of grid around it), held
/// at its base and pulled at its top, solved with the coarse grid (`linear = "two_level"`,
/// the 3D default): the nodes past its corners that only the B-spline stencils' tails
/// reach gave coarse rows of a few rounding quanta, which made the coarse stiffness
/// indefinite and stopped the solve; such rows are no longer coarse unknowns. Its strain
/// energy is the sparse factorization's within 1e-6 (both solves stop at 1e-8 of the load
/// or below; they agree to 1e-10). Those nodes' shape functions are nearly combinations of
/// their inward neighbours': Jacobi and the coarse grid took 435 iterations, the blocks of
/// weakly supported entries take 43 (asserted under 100, uGIMP's 41 on the same cube being
/// the mark), with the same bits on one thread and on two.
#[test]
fn a_b_spline_cube_solves_on_the_coarse_grid() {
    let cube = |linear: &str| {
        format!(
            r#"
[simulation]
dimension = 3
shape = "bspline"
duration = 1.0
solver = "static"
load_steps = 1
linear = "{linear}"
[grid]
min = [-0.002, -0.002, -0.002]
max = [0.008, 0.008, 0.008]
cell = [0.0005, 0.0005, 0.0005]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 8000.0
[[body]]
material = "steel"
box = {{ min = [0.0, 0.0, 0.0], max = [0.006, 0.006, 0.006] }}
[[boundary]]
region = {{ min = [-0.002, -0.002, -0.002], max = [0.008, 0.0, 0.008] }}
fix = ["x", "y", "z"]
[[load]]
region = {{ min = [0.0, 0.00575, 0.0], max = [0.006, 0.006, 0.006] }}
force = [0.0, 1000.0, 0.0]
"#
        )
    };
    let strain = |linear: &str| history(&cube(linear)).rows.last().unwrap().energies.strain;
    let (coarse, direct) = (strain("two_level"), strain("direct"));
    assert!(direct > 0.0);
    assert!(
        (coarse - direct).abs() / direct < 1e-6,
        "{coarse} vs {direct}"
    );
    let solved = common::run_text(&cube("two_level"))
        .summary
        .static_solve
        .unwrap();
    assert!(solved.iterations < 100, "{} iterations", solved.iterations);
    let one = final_world::<D3>(&cube("two_level"), 1);
    let two = final_world::<D3>(&cube("two_level"), 2);
    assert!(one.particles.x != one.particles.x0, "the cube stretched");
    assert_eq!(one.particles.x, two.particles.x);
}

/// The centre crack in a finite plate (scenarios/centre_crack_2d.toml) solved static in one
/// load step: K_I at both tips within 0.5 % of Tada's form of Feddersen's formula (good to
/// 0.1 %; the static solve reads -0.06 %, the damped explicit run +0.0003 %), K_II nil
/// against K_I; the crack-opening split, from the surfaces the solve moved, within 1 %
/// (it takes J's magnitude, which the 1 mm cells leave 0.3-0.4 % high both ways).
#[test]
fn centre_crack_solved_static() {
    let opts = fissure::app::run::RunOptions::default();
    let out = fissure::app::run::run(&switched("centre_crack_2d"), &opts).unwrap();
    let want = common::feddersen(100e6, 0.01, 0.02);
    let last = out.history.fracture.iter().map(|t| t.step).max().unwrap();
    let tips: Vec<_> = (out.history.fracture.iter())
        .filter(|t| t.step == last)
        .collect();
    assert_eq!(tips.len(), 2);
    for t in tips {
        assert!((t.k[0] - want).abs() / want < 5e-3, "{} vs {want}", t.k[0]);
        assert!(t.k[1].abs() < 1e-6 * want, "{}", t.k[1]);
        let opening = t.k_opening[0];
        assert!((opening - want).abs() / want < 1e-2, "{opening} vs {want}");
    }
}

/// The centre crack of scenarios/centre_crack_2d.toml solved static with its load turned
/// to compression, crack-face contact law `law` (None: no crack at all): the strain energy
/// at the end, K_I at the crack's end (0 without a crack), and the faces that closed.
fn compressed(law: Option<&str>) -> (f64, f64, usize) {
    let path = format!(
        "{}/scenarios/centre_crack_2d.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("force = [0.0, 4000.0]", "force = [0.0, -4000.0]")
        .replace(
            "force = [0.0, -4000.0]\ntime",
            "force = [0.0, 4000.0]\ntime",
        );
    match law {
        Some(law) => {
            let contact = format!("tips = [\"start\", \"end\"]\ncontact = {{ law = \"{law}\" }}");
            text = text.replace("tips = [\"start\", \"end\"]", &contact);
        }
        None => {
            let crack = text.find("[[crack]]").unwrap();
            let loads = text.find("[[load]]").unwrap();
            text.replace_range(crack..loads, "");
            let fracture = text.find("[fracture]").unwrap();
            text.truncate(fracture);
        }
    }
    let set = [
        "simulation.solver=\"static\"".to_string(),
        "simulation.load_steps=1".to_string(),
    ];
    let src = fissure::io::scenario::Source::parse(&path, &text, &set).unwrap();
    let out = fissure::app::run::run(&src, &Default::default()).unwrap();
    let strain = out.summary.energies.strain;
    let k_i = out.history.fracture.last().map_or(0.0, |t| t.k[0]);
    (strain, k_i, out.summary.static_solve.unwrap().closed_faces)
}

/// A crack under compression normal to it: with frictionless contact its faces bear on
/// each other along their whole length and the plate stores the energy of the plate
/// without the crack, to the solve's residual (1e-8; it reads 3e-11), with K_I nil against
/// Feddersen's value (under 0.1 %; it reads 0); without contact the faces pass through
/// each other, the plate is 16 % softer and K_I reads minus Feddersen's value (within 1 %,
/// as in tension).
#[test]
fn a_crack_under_compression_closes() {
    let tada = common::feddersen(100e6, 0.01, 0.02);
    let (whole, _, _) = compressed(None);
    let (closed, k_closed, faces) = compressed(Some("frictionless"));
    let (open, k_open, none) = compressed(Some("none"));
    assert!(faces > 0 && none == 0, "{faces} {none}");
    assert!(
        (closed - whole).abs() <= 1e-8 * whole,
        "{closed} vs {whole}"
    );
    assert!(k_closed.abs() <= 1e-3 * tada, "{k_closed} vs {tada}");
    assert!((k_open + tada).abs() <= 1e-2 * tada, "{k_open} vs {tada}");
    assert!(open > closed * 1.01, "{open} vs {closed}");
}

/// A plate 40 x 120 mm (1 mm cells, plane strain) pressed 100 MPa along its length, with a
/// crack 2a = 10 mm through its centre at 30 degrees to its width (or none), contact law
/// `law`, solved static: the strain energy, K from the opening at the crack's end, and the
/// faces that closed.
fn pressed_slant(law: Option<&str>) -> (f64, [f64; 3], usize) {
    let crack = law.map_or(String::new(), |law| {
        let (c, s) = (
            0.005 * 30f64.to_radians().cos(),
            0.005 * 30f64.to_radians().sin(),
        );
        format!(
            "[[crack]]\nname = \"slant\"\nline = {{ start = [{}, {}], end = [{}, {}] }}\n\
             contact = {{ law = \"{law}\" }}\n[fracture]\ncontour = 3\n",
            0.02 - c,
            0.0601 - s,
            0.02 + c,
            0.0601 + s
        )
    });
    let text = format!(
        r#"
[simulation]
dimension = 2
plane = "strain"
solver = "static"
duration = 1.0
load_steps = 1
[grid]
min = [-0.002, -0.002]
max = [0.042, 0.122]
cell = [0.001, 0.001]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "steel"
box = {{ min = [0.0, 0.0], max = [0.04, 0.12] }}
[[load]]
region = {{ min = [0.0, 0.1195], max = [0.04, 0.12] }}
force = [0.0, -4.0e6]
time = {{ kind = "table", points = [[0.0, 0.0], [1.0, 1.0]] }}
[[load]]
region = {{ min = [0.0, 0.0], max = [0.04, 0.0005] }}
force = [0.0, 4.0e6]
time = {{ kind = "table", points = [[0.0, 0.0], [1.0, 1.0]] }}
{crack}
"#
    );
    let out = common::run_text(&text);
    let opening = out
        .history
        .fracture
        .last()
        .map_or([0.0; 3], |t| t.k_opening);
    let faces = out.summary.static_solve.unwrap().closed_faces;
    (out.summary.energies.strain, opening, faces)
}

/// A slanted crack pressed shut: its faces carry compression and, at 30 degrees to the
/// load, the shear tau = 100 MPa sin 30 cos 30. Frictionless faces close and slide: the
/// plate is softer than without the crack (0.8 %) and stiffer than with faces that pass
/// through each other; the opening's K_II is the inclined crack's tau sqrt(pi a) within
/// 15 % (it reads +9 %: the plate's width adds about 3 %, the 10-cell crack the rest), and
/// its K_I under 5 % of that (the faces do not open: it reads -0.24 MPa sqrt(m) against
/// -9.4 with the faces passing through each other). The interaction integral's K_I reads
/// -6.5 MPa sqrt(m) here: its domain form takes the faces as free of traction, and the
/// contact pressure's work on the auxiliary mode I opening is left in it (not asserted:
/// docs/fracture.md).
#[test]
fn a_slanted_crack_pressed_shut_slides() {
    let (whole, _, _) = pressed_slant(None);
    let (sliding, opening, faces) = pressed_slant(Some("frictionless"));
    let (through, _, none) = pressed_slant(Some("none"));
    let tau = 100e6 * 30f64.to_radians().sin() * 30f64.to_radians().cos();
    let closed_form = tau * (std::f64::consts::PI * 0.005).sqrt();
    assert!(faces > 0 && none == 0, "{faces} {none}");
    assert!(
        sliding > whole * 1.002 && through > sliding * 1.002,
        "{whole} < {sliding} < {through}"
    );
    assert!(
        (opening[1].abs() / closed_form - 1.0).abs() < 0.15,
        "{opening:?} vs {closed_form}"
    );
    assert!(opening[0].abs() < 0.05 * closed_form, "{opening:?}");
}

/// A plate 60 x 60 mm (1 mm cells, plane strain) with sigma_yy = -100 MPa and tau_xy = 50
/// MPa on its edges, a crack 2a = 10 mm on its mid-plane with contact law `law` (None: no
/// crack), solved static in `steps` load steps of a load rising in proportion: the strain
/// energy, the external work and the work of friction, from summary.json's energies.
fn sheared_shut(law: Option<&str>, steps: usize) -> (f64, f64, f64) {
    sheared_shut_as(law, steps, "")
}

/// [`sheared_shut`] with `model` added to the steel's keys.
fn sheared_shut_as(law: Option<&str>, steps: usize, model: &str) -> (f64, f64, f64) {
    let text = common::sheared_plate(0.001, 0.005, law, steps, model);
    let e = common::run_text(&text).summary.energies;
    (e.strain, e.external_work, e.friction_work)
}

/// A crack pressed shut (sigma = 100 MPa) and sheared (tau = 50 MPa) with Coulomb faces.
/// With mu = 0.6 > tau / sigma the faces stick and the plate stores the energy of the
/// plate without the crack (within 1e-5; it reads 5.5e-7: slip only at the tips, where
/// the discrete stresses peak, dissipating 6e-6 of the work). With mu = 0.2 and 0.4 the
/// faces slide against mu sigma, so (Bueckner's superposition) the slip is the
/// frictionless crack's times (tau - mu sigma) / tau, and the friction's work, mu sigma
/// times half the slip integrated over the faces on a linear ramp, is mu sigma (tau - mu
/// sigma) / tau^2 times the frictionless crack's extra strain energy: within 3 % (it reads
/// -0.5 and +2.3 %; the plate's size and the discrete crack's compliance cancel in the
/// ratio, while the friction forces follow the nodal normal forces, which differ from a
/// uniform mu sigma near the tips). Energy balances: the loads' work is the strain energy
/// plus the friction's to 1e-8 on one load step (the trapezoid is exact on a linear step).
/// On three load steps the faces slide step by step from where the particles say they
/// were: the friction's work stays within 0.5 % of one step's (it reads -0.17 %), and the
/// balance within 1e-5 (it reads 1.9e-6: a pair that sticks part of a step is not linear
/// over it).
#[test]
fn coulomb_faces_stick_or_slide_as_the_law_says() {
    let (sigma, tau) = (100e6, 50e6);
    let (whole, _, _) = sheared_shut(None, 1);
    let (frictionless, _, _) = sheared_shut(Some("{ law = \"frictionless\" }"), 1);
    let friction = |mu: f64, steps: usize| {
        let law = format!("{{ law = \"friction\", friction = {mu} }}");
        sheared_shut(Some(&law), steps)
    };
    let (stuck, work, rubbed) = friction(0.6, 1);
    assert!((stuck - whole).abs() <= 1e-5 * whole, "{stuck} vs {whole}");
    assert!(rubbed <= 1e-4 * work, "{rubbed} of {work}");
    for mu in [0.2, 0.4] {
        let expected = mu * sigma * (tau - mu * sigma) / (tau * tau) * (frictionless - whole);
        slides_as_superposed(friction(mu, 1), expected, 0.03);
    }
    let (_, _, once) = friction(0.2, 1);
    let (strain, work, rubbed) = friction(0.2, 3);
    assert!((rubbed / once - 1.0).abs() < 5e-3, "{rubbed} vs {once}");
    assert!(
        (work - strain - rubbed).abs() <= 1e-5 * work,
        "{work} vs {strain} + {rubbed}"
    );
    // J2 plastic with a yield stress far above the stresses (Newton iterations, the
    // friction in their residual): in one load step the elastic answer to the Newton
    // tolerance (1e-8 of the load; the 14,400 particles take the coarse grid's inexact
    // solves, and the energies read 1.4e-8 apart); in three, the Newton path's ties act on each
    // step's increment, so a pair keeps the normal gap it had at the step's start where
    // the linear path's ties on the total close it, and the two differ by 2.7e-6 of the
    // work; the Newton path's balance holds to 1e-7 (it reads 5e-10).
    let law = "{ law = \"friction\", friction = 0.2 }";
    let j2 = "model = \"j2\"\nsigma_y = 5e9";
    let (strain_1, work_1, rubbed_1) = friction(0.2, 1);
    let (strain_p, work_p, rubbed_p) = sheared_shut_as(Some(law), 1, j2);
    for (a, b) in [(strain_p, strain_1), (work_p, work_1), (rubbed_p, rubbed_1)] {
        assert!((a - b).abs() <= 1e-7 * b.abs(), "{a} vs {b}");
    }
    let (strain_p, work_p, rubbed_p) = sheared_shut_as(Some(law), 3, j2);
    assert!((work_p - work).abs() <= 1e-5 * work, "{work_p} vs {work}");
    assert!(
        (work_p - strain_p - rubbed_p).abs() <= 1e-7 * work_p,
        "{work_p} vs {strain_p} + {rubbed_p}"
    );
}

/// A 40 mm cube (2 mm cells, 64,000 particles) with sigma_yy = -100 MPa and tau_xy = 50
/// MPa on its faces and a penny of radius 8 mm on its mid-plane with contact law `law`
/// (None: no crack), solved static in one load step: the strain energy, the external work
/// and the work of friction.
fn sheared_penny(law: Option<&str>) -> (f64, f64, f64) {
    let (strain, work, rubbed, _) = sheared_penny_as(law, [0.0, 1.0, 0.0], "auto");
    (strain, work, rubbed)
}

/// [`sheared_penny`] with the penny's unit `normal` and the `linear` solver given, also
/// returning the face pairs closed.
fn sheared_penny_as(law: Option<&str>, normal: [f64; 3], linear: &str) -> (f64, f64, f64, usize) {
    let crack = law.map_or(String::new(), |law| {
        format!(
            "[[crack]]\nname = \"penny\"\npenny = {{ center = [0.0, 0.0, 0.0], normal = \
             {normal:?}, radius = 0.008 }}\ncontact = {law}\n"
        )
    });
    let face = common::ramped_load::<3>;
    // Face tractions (t = sigma . n) times the 40 x 40 mm faces.
    let (a, b) = (0.02, 0.019);
    let loads = [
        face([-a, b, -a], [a, a, a], [8.0e4, -1.6e5, 0.0]),
        face([-a, -a, -a], [a, -b, a], [-8.0e4, 1.6e5, 0.0]),
        face([b, -a, -a], [a, a, a], [0.0, 8.0e4, 0.0]),
        face([-a, -a, -a], [-b, a, a], [0.0, -8.0e4, 0.0]),
    ]
    .concat();
    let text = format!(
        r#"
[simulation]
dimension = 3
solver = "static"
duration = 1.0
load_steps = 1
linear = "{linear}"
[grid]
min = [-0.024, -0.024, -0.024]
max = [0.024, 0.024, 0.024]
cell = [0.002, 0.002, 0.002]
anchor = {{ point = [0.0, 0.0, 0.0], offset = [0.0, 0.5, 0.0] }}
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "steel"
box = {{ min = [-0.02, -0.02, -0.02], max = [0.02, 0.02, 0.02] }}
{loads}
{crack}
"#
    );
    let out = common::run_text(&text);
    let (e, faces) = (out.summary.energies, out.summary.static_solve.unwrap());
    (
        e.strain,
        e.external_work,
        e.friction_work,
        faces.closed_faces,
    )
}

/// The 2D test's superposition on a penny pressed shut and sheared (mu = 0.2): its faces
/// slide in the plane of the crack, and the friction's work is mu sigma (tau - mu sigma) /
/// tau^2 = 0.24 times the frictionless penny's extra strain energy, within 3 % (it reads
/// -0.84 %); the loads' work is the strain energy plus the friction's to 1e-8.
#[test]
fn coulomb_faces_slide_on_a_penny() {
    let (whole, _, _) = sheared_penny(None);
    let (frictionless, _, _) = sheared_penny(Some("{ law = \"frictionless\" }"));
    let rubbing = sheared_penny(Some("{ law = \"friction\", friction = 0.2 }"));
    slides_as_superposed(rubbing, 0.24 * (frictionless - whole), 0.03);
}

/// Conjugate gradients on closed frictionless faces whose normal, (1, 1, 1) / sqrt 3, is
/// oblique to every axis: the Jacobi diagonal of a pair tied along n is folded as a
/// diagonal (a rotation of D's terms, never negative), not as a force, which had left zero
/// or negative diagonal entries replaced by 1 N/m (twelve orders below the others) and
/// stalled the iteration. Jacobi and the coarse grid each reach the direct solve's closed
/// pairs and strain energy (within 1e-7; they read 1.1e-9 and 1.9e-10).
#[test]
fn conjugate_gradients_solve_faces_closed_across_the_axes() {
    let r = 1.0 / 3f64.sqrt();
    let law = Some("{ law = \"frictionless\" }");
    let (direct, _, _, faces) = sheared_penny_as(law, [r, r, r], "direct");
    assert!(faces > 0, "no face closed");
    for linear in ["cg", "two_level"] {
        let (strain, _, _, closed) = sheared_penny_as(law, [r, r, r], linear);
        assert_eq!(closed, faces, "{linear}");
        assert!(
            (strain - direct).abs() <= 1e-7 * direct,
            "{linear}: {strain} vs {direct}"
        );
    }
}

/// Coulomb faces (mu = 0.2) on the sheared penny with its normal along (0.3, 0.9, 0.3),
/// oblique to every axis: pressed at sigma_n = -54.5 MPa and sheared at tau = 68.9 MPa on
/// its plane, it slides as the superposition says, mu sigma (tau - mu sigma) / tau^2 =
/// 0.133 times the frictionless penny's extra strain energy; within 5 % (it reads -3.8 %,
/// against -0.84 % on the penny along the grid: the crack cutting the cells obliquely
/// spreads the nodal normal forces less evenly than the uniform pressure of the
/// superposition). Without the friction's tangent in K its slip directions cycled and the
/// active set did not settle in 50 rounds.
#[test]
fn coulomb_faces_slide_on_a_penny_oblique_to_the_grid() {
    let n = [0.3, 0.9, 0.3];
    let (whole, _, _, _) = sheared_penny_as(None, n, "auto");
    let (frictionless, _, _, _) = sheared_penny_as(Some("{ law = \"frictionless\" }"), n, "auto");
    let (strain, work, rubbed, closed) =
        sheared_penny_as(Some("{ law = \"friction\", friction = 0.2 }"), n, "auto");
    assert!(closed > 0, "no face closed");
    let length = n.iter().map(|x| x * x).sum::<f64>().sqrt();
    let m: Vec<f64> = n.iter().map(|x| x / length).collect();
    // sigma = [[0, 50, 0], [50, -100, 0], [0, 0, 0]] MPa (the loads of `sheared_penny_as`).
    let t = [50.0 * m[1], 50.0 * m[0] - 100.0 * m[1], 0.0];
    let sigma_n: f64 = (0..3).map(|a| t[a] * m[a]).sum();
    let tau = (0..3)
        .map(|a| (t[a] - sigma_n * m[a]).powi(2))
        .sum::<f64>()
        .sqrt();
    let (mu, pressed) = (0.2, -sigma_n);
    let expected = mu * pressed * (tau - mu * pressed) / (tau * tau) * (frictionless - whole);
    slides_as_superposed((strain, work, rubbed), expected, 0.05);
}

/// Asserts a sliding crack's one-step energies (strain, external work, friction work):
/// the friction's work within `tolerance` of the superposition's `expected`, and the loads'
/// work equal to the strain energy plus the friction's to 1e-8.
fn slides_as_superposed((strain, work, rubbed): (f64, f64, f64), expected: f64, tolerance: f64) {
    assert!(
        (rubbed / expected - 1.0).abs() < tolerance,
        "{rubbed} vs {expected}"
    );
    assert!(
        (work - strain - rubbed).abs() <= 1e-8 * work,
        "{work} vs {strain} + {rubbed}"
    );
}

/// The end-notched flexure specimen (scenarios/enf_2d.toml: a beam in three-point bending
/// with a crack on its mid-plane, frictionless faces) solved static: K_II within 1 % of
/// the converged plane-stress FE value of the same beam (it reads -0.3 %).
#[test]
fn enf_solved_static() {
    let out = fissure::app::run::run(&switched("enf_2d"), &Default::default()).unwrap();
    let k_ii = out.history.fracture.last().unwrap().k[1];
    let fe = -1.198e5;
    assert!((k_ii - fe).abs() <= 1e-2 * fe.abs(), "{k_ii} vs {fe}");
}

/// The ENF's faces under Coulomb friction (mu = 0.3) over 30 load steps: the loads' work
/// equals the strain energy plus the friction's within 1e-4 (it reads 3e-6; the steps'
/// trapezoids). Each load step classifies the particles, at their initial places, against
/// the crack in the undeformed body: the arms sag by a third of a cell, and while the
/// crack moved with them each step split other particle-node pairs, and the friction work
/// booked on the new fields was 12 times the energy the faces took (the balance 7e-3 off).
#[test]
fn friction_over_load_steps_balances_the_energy() {
    let src = switched_with(
        "enf_2d",
        &[
            "crack[0].contact={law=\"friction\",friction=0.3}",
            "simulation.load_steps=30",
            "output.history_interval=2e-4",
        ],
    );
    let out = fissure::app::run::run(&src, &Default::default()).unwrap();
    let e = out.history.rows.last().unwrap().energies;
    assert!(e.friction_work > 0.0);
    assert!(
        (e.external_work - e.strain - e.friction_work).abs() <= 1e-4 * e.external_work,
        "{e:?}"
    );
}

/// The DCB turned 30 degrees to the grid, solved static: the particles at its loaded arm
/// ends sit on sliver nodes that only the ghost stiffness holds, and the run stops saying
/// so (the explicit solver runs this scene).
#[test]
fn a_load_on_a_mechanism_is_refused() {
    let opts = fissure::app::run::RunOptions::default();
    let e = match fissure::app::run::run(&switched("dcb_rotated_2d"), &opts) {
        Ok(_) => String::new(),
        Err(e) => format!("{e:#}"),
    };
    assert!(
        e.contains("ghost stiffness") && e.contains("particle"),
        "{e}"
    );
}

/// A steel bar 20 x 4 x 4 mm (1 mm cells, 2,560 particles; a quarter of a 20 x 8 x 8 mm
/// bar, with symmetry planes at y = 0 and z = 0) between two grips that hold x only, the
/// right one pulled 0.1 mm (5 times the yield strain) in 10 load steps, J2 with linear
/// hardening `h` (Pa). The state is uniaxial and uniform, its deviator's direction fixed,
/// and for linear hardening the radial return is exact along such a path: the grip's force
/// is A (sigma_0 + E H / (E + H) (eps - eps_0)) past yield and A E eps before it, to the
/// Newton tolerance (1e-8 of the force: 1e-6 holds it), and the plastic work is V
/// (sigma_0 eps_p + H eps_p^2 / 2) with eps_p = eps - sigma / E (the return's trapezoidal
/// dissipation is exact for linear hardening).
fn plastic_bar(h: f64) -> String {
    format!(
        r#"
[simulation]
dimension = 3
duration = 1.0
solver = "static"
load_steps = 10
[grid]
min = [-0.002, -0.002, -0.002]
max = [0.026, 0.006, 0.006]
cell = [0.001, 0.001, 0.001]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
model = "j2"
sigma_y = 250e6
H = {h:e}
[[body]]
material = "steel"
box = {{ min = [0.002, 0.0, 0.0], max = [0.022, 0.004, 0.004] }}
[[boundary]]
region = {{ min = [-0.002, -0.002, -0.002], max = [0.002, 0.006, 0.006] }}
fix = ["x"]
[[boundary]]
region = {{ min = [0.022, -0.002, -0.002], max = [0.026, 0.006, 0.006] }}
fix = ["x"]
velocity = [1e-4, 0.0, 0.0]
[[boundary]]
region = {{ min = [-0.002, -0.002, -0.002], max = [0.026, 0.0, 0.006] }}
fix = ["y"]
[[boundary]]
region = {{ min = [-0.002, -0.002, -0.002], max = [0.026, 0.006, 0.0] }}
fix = ["z"]
[[probe]]
name = "grip"
region = {{ min = [0.022, -0.002, -0.002], max = [0.026, 0.006, 0.006] }}
quantity = "reaction"
component = "x"
[output]
history_interval = 0.1
"#
    )
}

#[test]
fn a_plastic_bar_follows_the_uniaxial_hardening_law() {
    let (e, s0, area, length) = (200e9, 250e6, 1.6e-5, 0.02);
    for h in [0.0, 10e9] {
        let out = history(&plastic_bar(h));
        let mut yielded = 0;
        for (row, &force) in out.rows.iter().zip(&out.probes[0]).skip(1) {
            let eps = 1e-4 * row.time / length;
            let sigma = if eps <= s0 / e {
                e * eps
            } else {
                yielded += 1;
                s0 + e * h / (e + h) * (eps - s0 / e)
            };
            assert!(
                (force - area * sigma).abs() <= 1e-6 * area * sigma,
                "H = {h:e} at eps = {eps:e}: {force} vs {}",
                area * sigma
            );
            let eps_p = (eps - sigma / e).max(0.0);
            let work = area * length * (s0 * eps_p + 0.5 * h * eps_p * eps_p);
            let plastic = row.energies.plastic_work;
            assert!(
                (plastic - work).abs() <= 1e-6 * work.max(1e-3),
                "H = {h:e} at eps = {eps:e}: plastic work {plastic} vs {work}"
            );
        }
        assert!(yielded >= 7, "the bar yields in most steps");
    }
}

/// The same bar cut through at x = 12.1 mm and pushed 0.1 mm (5 times the yield strain in
/// compression), H = 10 GPa: with frictionless faces the cut closes and carries the
/// uniform uniaxial state, which the tied fields hold exactly (no shear across the cut), so
/// the grip's force is the uncut bar's -A (sigma_0 + E H / (E + H) (eps - eps_0)) to the
/// Newton tolerance (1e-6 of it); with open faces the halves pass through each other and
/// the grip pushes on nothing (under 1e-9 of that force).
#[test]
fn a_cut_plastic_bar_in_compression_closes() {
    let (e, s0, h, area, length) = (200e9, 250e6, 10e9, 1.6e-5, 0.02);
    let cut = |law: &str| {
        plastic_bar(h).replace(
            "velocity = [1e-4, 0.0, 0.0]",
            "velocity = [-1e-4, 0.0, 0.0]",
        ) + &format!(
            "[[crack]]\nname = \"cut\"\nrectangle = {{ center = [0.0121, 0.002, 0.002], axes = \
                 [[0.0, 0.003, 0.0], [0.0, 0.0, 0.003]] }}\ncontact = {{ law = \"{law}\" }}\n"
        )
    };
    let out = fissure::app::run::run(&source(&cut("frictionless")), &Default::default()).unwrap();
    assert!(out.summary.static_solve.unwrap().closed_faces > 0);
    let (rows, grip) = (&out.history.rows, &out.history.probes[0]);
    let (eps, force) = (
        1e-4 * rows.last().unwrap().time / length,
        *grip.last().unwrap(),
    );
    let sigma = s0 + e * h / (e + h) * (eps - s0 / e);
    assert!(
        (force + area * sigma).abs() <= 1e-6 * area * sigma,
        "{force} vs {}",
        -area * sigma
    );
    let open = history(&cut("none"));
    let pushed = *open.probes[0].last().unwrap();
    assert!(pushed.abs() <= 1e-9 * area * sigma, "{pushed}");
}

/// The same bar, perfectly plastic, under an end force that rises to 1.2 times its limit
/// load sigma_0 A over 10 load steps: the eight steps below the limit solve, the ninth
/// (1.08 times it) has no equilibrium, and the run stops there naming the step and what
/// failed instead of returning an answer.
#[test]
fn a_load_past_the_limit_load_stops_the_run() {
    let pulled = plastic_bar(0.0)
        .replace(
            r#"[[boundary]]
region = { min = [0.022, -0.002, -0.002], max = [0.026, 0.006, 0.006] }
fix = ["x"]
velocity = [1e-4, 0.0, 0.0]"#,
            r#"[[load]]
region = { min = [0.021, 0.0, 0.0], max = [0.022, 0.004, 0.004] }
force = [4800.0, 0.0, 0.0]
time = { kind = "ramp", rise = 1.0 }"#,
        )
        .replace(
            "region = { min = [0.022, -0.002, -0.002], max = [0.026, 0.006, 0.006] }\nquantity",
            "region = { min = [-0.002, -0.002, -0.002], max = [0.002, 0.006, 0.006] }\nquantity",
        );
    assert!(pulled.contains("force = [4800.0"));
    let opts = fissure::app::run::RunOptions::default();
    let e = match fissure::app::run::run(&source(&pulled), &opts) {
        Ok(o) => format!("ran to {:?}", o.summary.status),
        Err(e) => format!("{e:#}"),
    };
    assert!(
        e.contains("step 9") && e.contains("did not converge"),
        "{e}"
    );
}

/// Quasi-static fatigue growth (`solver = "static"`, one load step per check): an edge
/// crack on the mid-plane of a plate pulled symmetrically grows along that plane, so each
/// check's crack is the plate cut to that length from the start, and the K_I the check
/// reads must be that of a fresh static solve of the cut plate (to 1e-9: the two solve the
/// same system; the grown crack's vertices have moved along the plane by the earlier
/// steps' displacements, which leaves the classification as it was; they agree to the
/// last bit here). Each check grows one extension, five in all (checks at 12 to 28 us),
/// and the cycles rise at each.
#[test]
fn quasi_static_growth_reads_the_k_of_the_cut_plate() {
    let static_plate = |duration: f64, steps: u32| {
        common::edge_plate(common::PARIS_GROWTH, duration).replace(
            "[simulation]",
            &format!("[simulation]\nsolver = \"static\"\nload_steps = {steps}"),
        )
    };
    let out = fissure::app::run::run(&source(&static_plate(2.8e-5, 7)), &Default::default())
        .unwrap_or_else(|e| panic!("{e:#}"));
    let rows = &out.history.growth;
    assert_eq!(rows.len(), 5);
    for (n, g) in rows.iter().enumerate() {
        assert!((g.grown - 5e-4 * n as f64).abs() < 1e-12, "{}", g.grown);
        assert!(n == 0 || g.fatigue[1] > rows[n - 1].fatigue[1]);
        let cut = static_plate(4.0e-6, 1)
            .replace(
                "end = [0.002, 0.0]",
                &format!("end = [{:e}, 0.0]", 0.002 + g.grown),
            )
            .replace("at = 1.0e-5", "at = 1.0");
        let fresh = fissure::app::run::run(&source(&cut), &Default::default()).unwrap();
        let k = fresh.history.fracture.last().unwrap().k[0];
        assert!(
            (g.k[0] - k).abs() <= 1e-9 * k,
            "grown {}: {} against {k}",
            g.grown,
            g.k[0]
        );
    }
}

/// A crack that grows gives particles new entries of the same nodes, whose values the
/// coarse grid interpolates alike: the coarse stiffness stays what it was and its factor is
/// kept. The edge plate growing five extensions under `linear = "two_level"` factorizes the
/// coarse grid once, and every check reads the K_I of the direct solver's run to 1e-6
/// (both stop at 1e-8 of the load).
#[test]
fn a_growing_crack_keeps_the_coarse_factor() {
    let plate = |linear: &str| {
        let text = common::edge_plate(common::PARIS_GROWTH, 2.8e-5).replace(
            "[simulation]",
            &format!("[simulation]\nsolver = \"static\"\nload_steps = 7\nlinear = \"{linear}\""),
        );
        fissure::app::run::run(&source(&text), &Default::default())
            .unwrap_or_else(|e| panic!("{e:#}"))
    };
    let (coarse, direct) = (plate("two_level"), plate("direct"));
    let log = coarse.summary.static_solve.as_ref().unwrap();
    assert_eq!(log.coarse_factorizations, 1, "{log:?}");
    let (a, b) = (&coarse.history.growth, &direct.history.growth);
    assert_eq!((a.len(), b.len()), (5, 5));
    for (a, b) in a.iter().zip(b) {
        assert!((a.grown - b.grown).abs() < 1e-12, "{} {}", a.grown, b.grown);
        assert!(
            (a.k[0] - b.k[0]).abs() <= 1e-6 * b.k[0],
            "grown {}: {} against {}",
            a.grown,
            a.k[0],
            b.k[0]
        );
    }
}

/// A load step that changes nothing keeps the last answer: the cantilever's load ramped
/// over the first half of 8 load steps and held over the second. The four steps of the
/// hold solve nothing (no iterations, no factorization, no contact round); the tip ends
/// where one load step of the full load puts it (to 1e-12), and the clamp's reaction, taken
/// from the particles' stresses on the kept steps, balances the 100 N load to 1e-9.
#[test]
fn a_step_that_changes_nothing_keeps_the_last_answer() {
    let text = shipped("cantilever_static_2d");
    let ramped = text.replace("load_steps = 1", "load_steps = 8").replace(
        "force = [0.0, -100.0]     # N",
        "force = [0.0, -100.0]\ntime = { kind = \"ramp\", rise = 0.5 }",
    );
    assert!(ramped.contains("rise = 0.5") && ramped.contains("load_steps = 8"));
    let run = |text: &str| {
        fissure::app::run::run(&source(text), &Default::default())
            .unwrap_or_else(|e| panic!("{e:#}"))
    };
    let (held, once) = (run(&ramped), run(&text));
    let rows = &held.history.solves;
    assert_eq!(rows.len(), 8);
    for (k, r) in rows.iter().enumerate() {
        let s = &r.solved;
        assert_eq!(s.kept(), k >= 4, "load step {}: {s:?}", k + 1);
        if s.kept() {
            assert!(s.iterations == 0 && s.factorizations == 0, "{s:?}");
        }
    }
    let (tip, want) = (
        *held.history.probes[0].last().unwrap(),
        *once.history.probes[0].last().unwrap(),
    );
    assert!(
        (tip - want).abs() <= 1e-12 * want.abs(),
        "{tip} against {want}"
    );
    let reaction = *held.history.probes[1].last().unwrap();
    assert!((reaction - 100.0).abs() < 1e-7, "{reaction}");
    // A ramp of 0.1 s over 7 load steps of 0.7 s: the first step ends at
    // 0.09999999999999999 s, a rounding short of the ramp's top; the six after it keep
    // the answer all the same.
    let rounded = text
        .replace("load_steps = 1", "load_steps = 7")
        .replace("duration = 1.0", "duration = 0.7")
        .replace(
            "force = [0.0, -100.0]     # N",
            "force = [0.0, -100.0]\ntime = { kind = \"ramp\", rise = 0.1 }",
        );
    assert!(rounded.contains("duration = 0.7") && rounded.contains("rise = 0.1"));
    let out = run(&rounded);
    assert!(
        out.history.solves[0].time < 0.1,
        "{}",
        out.history.solves[0].time
    );
    let kept: Vec<bool> = (out.history.solves.iter())
        .map(|r| r.solved.kept())
        .collect();
    assert_eq!(kept, [false, true, true, true, true, true, true]);
    let tip = *out.history.probes[0].last().unwrap();
    assert!(
        (tip - want).abs() <= 1e-12 * want.abs(),
        "{tip} against {want}"
    );
}

/// solver.csv: one row per load step (numbered 1 to n), each under the scene's tolerance,
/// their Newton iterations adding up to summary.json's total; the file holds the rows the
/// history keeps (and a resumed run rewrites them: `tests/snapshot.rs`).
#[test]
fn each_load_step_writes_its_solve_row() {
    let text = coarse_cylinder("");
    let dir = std::env::temp_dir().join(format!("fissure-solver-csv-{}", std::process::id()));
    let opts = fissure::app::run::RunOptions {
        out: Some(dir.clone()),
        ..Default::default()
    };
    let out = fissure::app::run::run(&source(&text), &opts).unwrap_or_else(|e| panic!("{e:#}"));
    let rows = &out.history.solves;
    let log = out.summary.static_solve.unwrap();
    assert_eq!(rows.len() as u64, log.load_steps);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r.step, k as u64 + 1);
        assert!(r.solved.residual <= 1e-8 && r.solved.newton >= 1, "{r:?}");
    }
    let newton: usize = rows.iter().map(|r| r.solved.newton).sum();
    assert_eq!(newton as u64, log.newton_iterations);
    let file = std::fs::read_to_string(dir.join("solver.csv")).unwrap();
    let lines: Vec<&str> = file.lines().collect();
    assert!(lines[0].starts_with("step,time,newton,iterations,factorizations,residual"));
    assert_eq!(lines.len(), rows.len() + 1);
    for (line, r) in lines[1..].iter().zip(rows) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells[0], r.step.to_string());
        assert_eq!(cells[2], r.solved.newton.to_string());
        assert_eq!(cells[4], r.solved.factorizations.to_string());
    }
    std::fs::remove_dir_all(dir).ok();
}

/// The plane-stress bar of scenarios/bar_plastic_2d.toml (modified Ramberg-Osgood, n = 10)
/// solved static in 40 load steps: each Newton iteration takes the projected return's
/// tangent by central differences. Pulled to 8e-3 the bar carries the uniaxial law's
/// sigma_0 (8e-3 / 1.25e-3)^(1/10) = 300.99 MPa within 1e-4 (it reads 1.4e-5: the
/// scenario's reference is rounded to 5 digits), unloads along E to 1e-9 (a uniform
/// strain lies in the shape functions' span), and no load step takes more than 6 Newton
/// iterations (a tangent that were not the return's derivative would take dozens).
#[test]
fn a_plane_stress_plastic_bar_solves_static() {
    let text = shipped("bar_plastic_2d");
    let set = [
        "simulation.solver=\"static\"".to_string(),
        "simulation.load_steps=40".to_string(),
    ];
    let src = fissure::io::scenario::Source::parse("bar_plastic_2d.toml", &text, &set).unwrap();
    let out = fissure::app::run::run(&src, &Default::default()).unwrap_or_else(|e| panic!("{e:#}"));
    let expect = |reference: f64| {
        let e = (out.summary.expects.iter())
            .find(|e| (e.reference - reference).abs() <= 1e-9 * reference.abs())
            .unwrap_or_else(|| panic!("an expect of {reference}"));
        e.error.unwrap()
    };
    assert!(expect(3.0099e8) < 1e-4, "{}", expect(3.0099e8));
    assert!(expect(200e9) < 1e-9, "{}", expect(200e9));
    let log = out.summary.static_solve.unwrap();
    assert!(
        log.most_newton <= 6 && log.worst_residual <= 1e-8,
        "{log:?}"
    );
}

/// Lame's shell of [`common::pressed_shell`] solved static in one step (in 3D by the
/// direct solver), with `nu` and the dilatation given: the x displacements at r = 0.15 m
/// next to the x axis and on the diagonal.
fn pressed_shell(dim: usize, nu: f64, dilatation: &str) -> (f64, f64) {
    let linear = if dim == 3 {
        "linear = \"direct\"\n"
    } else {
        ""
    };
    let simulation = format!(
        "{linear}solver = \"static\"\nduration = 1.0\nload_steps = 1\ndilatation = \"{dilatation}\""
    );
    let text = common::pressed_shell(dim, nu, &simulation, "[[0.0, 0.0], [1.0, 1.0]]");
    let h = history(&text);
    (*h.probes[0].last().unwrap(), *h.probes[1].last().unwrap())
}

/// Lame's thick cylinder, nearly incompressible (nu = 0.4999), against the closed form
/// u(r) = (1 + nu) p a^2 / (E (b^2 - a^2)) ((1 - 2 nu) r + b^2 / r). With each particle's
/// own dilatation the 2 x 2 particles of a cell put four volume constraints on about one
/// node's two motions, and the ring locks: the diagonal, where the cells lie obliquely to
/// the flow, moves far less than it should (it reads 42 % low). With the cell's mean
/// dilatation (`dilatation = "cell_mean"`) it reads within 1.5 % on the diagonal and 2 % on
/// the axis: the bounds the same cells meet at nu = 0.3 (0.4 % and 1.3 %; checked here
/// too, so a loss of accuracy in the compressible case would show), with room for the
/// pressure's band of particles, which this discretization spreads over half a cell.
#[test]
fn cell_mean_dilatation_unlocks_a_nearly_incompressible_cylinder() {
    let lame = |nu: f64, r: f64| {
        let (e, p, a, b) = (200e9, 100e6, 0.1, 0.2);
        (1.0 + nu) * p * a * a / (e * (b * b - a * a)) * ((1.0 - 2.0 * nu) * r + b * b / r)
    };
    let (axis_r, diagonal_r) = (0.15f64.hypot(0.0025), 0.15);
    let cos45 = 0.5f64.sqrt();
    for nu in [0.3, 0.4999] {
        let (axis, diagonal) = pressed_shell(2, nu, "cell_mean");
        let want_axis = lame(nu, axis_r) * 0.15 / axis_r;
        let want_diagonal = lame(nu, diagonal_r) * cos45;
        assert!(
            (axis / want_axis - 1.0).abs() < 0.02,
            "nu {nu}: {axis} vs {want_axis}"
        );
        assert!(
            (diagonal / want_diagonal - 1.0).abs() < 0.015,
            "nu {nu}: {diagonal} vs {want_diagonal}"
        );
    }
    let (_, locked) = pressed_shell(2, 0.4999, "particle");
    let want = lame(0.4999, diagonal_r) * cos45;
    assert!(
        locked < 0.8 * want,
        "{locked} vs {want}: the case does lock"
    );
}

/// The assembled B-bar stiffness of the cell-mean dilatation is the matrix-free product's
/// matrix: the plastic cylinder of scenarios/cylinder_plastic_2d.toml (7.5 mm cells) solved
/// by the direct solver and by conjugate gradients, each Newton step to a residual of 1e-8,
/// reaches the same stresses within 1e-6 of the largest, in as few Newton iterations as
/// with each particle's own dilatation, to one: at most 6 a step with exact linear solves,
/// 7 with the conjugate gradients' inexact ones (a tangent that were not the operator's
/// derivative would take dozens).
#[test]
fn cell_mean_dilatation_assembles_the_operator_it_applies() {
    let solve = |linear: &str| {
        let t = coarse_cylinder(&format!(
            "dilatation = \"cell_mean\"\nlinear = \"{linear}\""
        ));
        let out = common::run_text(&t);
        let most = out.summary.static_solve.unwrap().most_newton;
        (final_world::<D2>(&t, 2).particles.stress, most)
    };
    let (direct, most_direct) = solve("direct");
    let (cg, most_cg) = solve("cg");
    same_stresses(&direct, &cg);
    assert!(most_direct <= 6 && most_cg <= 7, "{most_direct}, {most_cg}");
}

/// Under "auto" a 2D plastic scene of 10^4 particles or more (nu at most 0.35) is solved by
/// conjugate gradients with the coarse grid (factorized once), not by a factorization per
/// Newton iteration: Hill's cylinder at its shipped 2.5 mm cells (15,086 particles) takes the
/// coarse grid and reaches the direct solve's stresses within 1e-6 of the largest (each
/// Newton step converged to 1e-8 of the load), while on 7.5 mm cells (1,669 particles), or
/// with nu = 0.45, it stays direct.
#[test]
fn auto_takes_the_coarse_grid_for_large_plastic_scenes() {
    let shipped = |linear: &str| cylinder(&format!("linear = \"{linear}\""));
    let log = |t: &str| common::run_text(t).summary.static_solve.unwrap();
    let auto = log(&shipped("auto"));
    assert!(
        auto.coarse_factorizations == 1 && auto.factorizations == 0 && auto.iterations > 0,
        "{auto:?}"
    );
    let direct_kept = |t: &str| {
        let s = log(t);
        assert!(
            s.factorizations > 0 && s.coarse_factorizations == 0,
            "{s:?}"
        );
    };
    direct_kept(&coarse_cylinder(""));
    direct_kept(&shipped("auto").replace("nu = 0.3", "nu = 0.45"));
    let stress = |t: &str| final_world::<D2>(t, 2).particles.stress;
    let (direct, coarse) = (stress(&shipped("direct")), stress(&shipped("auto")));
    same_stresses(&direct, &coarse);
}

/// Asserts that two solves' particle stresses agree within 1e-6 of the first's largest
/// normal stress: the Newton tolerance (1e-8 of the load) leaves far less between them.
fn same_stresses(a: &[fissure::base::sym::Sym2], b: &[fissure::base::sym::Sym2]) {
    let scale = a
        .iter()
        .map(|s| s.xx.abs().max(s.yy.abs()))
        .fold(0.0, f64::max);
    let worst = (a.iter().zip(b))
        .map(|(a, b)| {
            (a.xx - b.xx)
                .abs()
                .max((a.yy - b.yy).abs())
                .max((a.xy - b.xy).abs())
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-6 * scale, "{worst} of {scale}");
}

/// Lame's thick sphere in 3D, u(r) = p a^3 / (E (b^3 - a^3)) ((1 - 2 nu) r + (1 + nu) b^3
/// / (2 r^2)), nearly incompressible (nu = 0.499): with each particle's own dilatation
/// the 2 x 2 x 2 particles of a cell lock it, and the diagonal reads 43 % low (the axis 13 %
/// high); with the cell's mean the diagonal reads 0.4 % and the axis 3.9 % low, within the
/// 5 % these coarse cells are held to (at nu = 0.3 they read +1.4 % and -1.1 %, checked
/// too).
#[test]
fn cell_mean_dilatation_unlocks_a_nearly_incompressible_sphere() {
    let lame = |nu: f64, r: f64| {
        let (e, p, a, b) = (200e9, 100e6, 0.1f64, 0.2f64);
        p * a.powi(3) / (e * (b.powi(3) - a.powi(3)))
            * ((1.0 - 2.0 * nu) * r + (1.0 + nu) * b.powi(3) / (2.0 * r * r))
    };
    for nu in [0.3, 0.499] {
        let (axis, diagonal) = pressed_shell(3, nu, "cell_mean");
        let want_diagonal = lame(nu, 0.15) / 3f64.sqrt();
        let want_axis = lame(nu, 0.15);
        assert!(
            (diagonal / want_diagonal - 1.0).abs() < 0.05,
            "nu {nu}: {diagonal} vs {want_diagonal}"
        );
        assert!(
            (axis / want_axis - 1.0).abs() < 0.05,
            "nu {nu}: {axis} vs {want_axis}"
        );
    }
    let (_, locked) = pressed_shell(3, 0.499, "particle");
    let want = lame(0.499, 0.15) / 3f64.sqrt();
    assert!(
        locked < 0.8 * want,
        "{locked} vs {want}: the case does lock"
    );
}

/// Runs `text` and asserts that faces closed and rubbed, and that the loads' work equals
/// the strain energy plus the friction's within `tolerance` of itself.
fn rubs_and_balances(text: &str, tolerance: f64) {
    let out = common::run_text(text);
    let e = out.summary.energies;
    assert!(out.summary.static_solve.unwrap().closed_faces > 0);
    assert!(e.friction_work > 0.0);
    assert!(
        (e.external_work - e.strain - e.friction_work).abs() <= tolerance * e.external_work,
        "{e:?}"
    );
}

/// An elliptical crack at an oblique tilt (normal about (0.31, -0.38, 0.87)) in the
/// pressed cube, its top pressed by 100 MPa and sheared by 50 MPa, mu = 0.2, four load
/// steps (one of 40 random scenes): the particles near its front own crack fields that no
/// other particle reaches, whose friction loaded motions nothing but the ghost holds (the
/// second load step stopped, 67 % of the work on the ghost). It solves, and the loads'
/// work is the strain energy plus the friction's within 1e-4 (it reads 1.1e-5; the load
/// steps' trapezoids for the friction's work).
#[test]
fn friction_leaves_fields_of_a_lone_particle_alone() {
    let ellipse = "{ center = [0.014497, 0.013514, 0.012051], axes = [[-0.0060298, \
                   0.00058676, 0.002395], [-0.0012549, -0.0052853, -0.0018644]] }";
    let text = common::pressed_cube([9136.75, -90000.0, 44246.16], ellipse, 0.2, 4);
    rubs_and_balances(&text, 1e-4);
}

/// An oblique elliptical crack in the pressed cube, pressed shut by 100 MPa and sheared by
/// 17 MPa with mu = 0.6 (one of 40 random scenes, solved in one load step): the friction
/// forces' sizes swung between rounds, each a little less, 3 % a round (the normal forces
/// and the friction forces feed each other), and the active set did not settle in 50
/// rounds; a pair whose size turns back on its last change now takes half the step, and
/// it settles (in 18). The loads' work equals the strain energy plus the friction's to
/// 1e-8 (one load step: round-off, it reads 1e-11).
#[test]
fn friction_forces_that_swing_between_rounds_settle() {
    let ellipse = "{ center = [0.017631, 0.015075, 0.012775], axes = [[0.0030610, \
                   -0.0050832, -0.0049230], [-0.0050739, -0.0025233, -0.00054946]] }";
    let text = common::pressed_cube([14941.66, -90000.0, -4883.99], ellipse, 0.6, 1);
    rubs_and_balances(&text, 1e-8);
}
