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
/// carries the weight to the solver's tolerance; the strain energy equals half the work of
/// gravity (Clapeyron), as energy.csv's balance says.
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

/// The cantilever of scenarios/cantilever_static_2d.toml on one thread and on two: the
/// same bits in every particle's position and stress.
#[test]
fn static_solve_is_the_same_on_any_thread_count() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/cantilever_static_2d.toml"
    ))
    .unwrap();
    let one = final_world::<D2>(&text, 1);
    let two = final_world::<D2>(&text, 2);
    assert!(one.particles.x != one.particles.x0, "the beam bent");
    assert_eq!(one.particles.x, two.particles.x);
    assert_eq!(
        format!("{:?}", one.particles.stress),
        format!("{:?}", two.particles.stress)
    );
}

/// A crack, a plastic material and a moving boundary are refused in a static scene,
/// naming the key; load steps in an explicit scene too.
#[test]
fn what_the_static_solver_does_not_take_is_refused() {
    let err = |text: String| match build::<D3>(&source(&text)) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    };
    let crack = column(
        "[[crack]]\nname = \"c\"\nrectangle = { center = [0.005, 0.005, 0.05], axes = \
         [[0.003, 0.0, 0.0], [0.0, 0.003, 0.0]] }",
    );
    let e = err(crack);
    assert!(e.contains("crack[0]") && e.contains("cracks"), "{e}");
    let plastic = column("").replace(
        "rho = 8000.0",
        "rho = 8000.0\nmodel = \"j2\"\nsigma_y = 250e6",
    );
    let e = err(plastic);
    assert!(e.contains("material[0]") && e.contains("plasticity"), "{e}");
    let moving = column("").replace("fix = [\"z\"]", "fix = [\"z\"]\nvelocity = [0.0, 0.0, 1.0]");
    let e = err(moving);
    assert!(e.contains("boundary[0].velocity"), "{e}");
    let explicit = column("").replace("solver = \"static\"\n", "");
    let e = err(explicit);
    assert!(e.contains("simulation.load_steps"), "{e}");
}

/// A column with nothing to stand on: gravity would start it moving, so equilibrium has no
/// solution, and the run stops saying so rather than returning a meaningless answer.
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
    assert!(e.contains("did not converge") && e.contains("rigid"), "{e}");
}
