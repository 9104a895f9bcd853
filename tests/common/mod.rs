//! Helpers shared by the integration tests: scenario text for bars, running to a history.
#![allow(dead_code)]

pub mod mesh;

use fissure::app::run::{Outcome, RunOptions, run};
use fissure::io::scenario::{Source, build};
use fissure::pipeline::schedule::{Schedule, System};
use fissure::record::history::History;
use fissure::store::world::World;
use fissure::systems::DimSystems;

/// Parses scenario text (panics with the located error if it does not parse).
pub fn source(text: &str) -> Source {
    Source::parse("test.toml", text, &[]).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs scenario text without writing files.
pub fn run_text(text: &str) -> Outcome {
    run(&source(text), &RunOptions::default()).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Runs scenario text and returns its history.
pub fn history(text: &str) -> History {
    run_text(text).history
}

/// Builds the scene and steps it to the end on `threads` threads, returning the world.
pub fn final_world<D: DimSystems>(text: &str, threads: usize) -> World<D> {
    final_world_with(text, threads, |_| {})
}

/// As [`final_world`], with `prepare` applied to the world before the first step.
pub fn final_world_with<D: DimSystems>(
    text: &str,
    threads: usize,
    prepare: impl FnOnce(&mut World<D>) + Send,
) -> World<D> {
    let src = source(text);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let scene = build::<D>(&src).unwrap_or_else(|e| panic!("{e}"));
        let mut world = scene.world;
        prepare(&mut world);
        let mut schedule = Schedule::for_world(&world, None);
        let steps = fissure::app::run::step_count(scene.duration, world.settings.dt);
        while world.step < steps {
            schedule.step(&mut world).unwrap_or_else(|e| panic!("{e}"));
        }
        world
    })
}

/// A D-dimensional list "[a, b(, c)]" with `first` on x and `rest` on the other axes.
pub fn v(dim: usize, first: f64, rest: f64) -> String {
    let mut parts = vec![format!("{first:e}")];
    parts.extend((1..dim).map(|_| format!("{rest:e}")));
    format!("[{}]", parts.join(", "))
}

/// A bar along x: length `len`, square section `w`, cell `h`, margins of two cells.
pub struct Bar {
    pub dim: usize,
    pub len: f64,
    pub w: f64,
    pub h: f64,
    pub e: f64,
    pub nu: f64,
    pub rho: f64,
    pub shape: &'static str,
    pub update: &'static str,
    pub plane: &'static str,
    pub duration: f64,
    pub damping: f64,
    pub velocity: f64,
    /// Extra TOML appended (loads, boundaries, probes).
    pub extra: String,
}

impl Default for Bar {
    fn default() -> Self {
        Bar {
            dim: 2,
            len: 0.1,
            w: 0.01,
            h: 0.002,
            e: 200e9,
            nu: 0.0,
            rho: 8000.0,
            shape: "ugimp",
            update: "usavg",
            plane: "stress",
            duration: 1e-5,
            damping: 0.0,
            velocity: 0.0,
            extra: String::new(),
        }
    }
}

impl Bar {
    /// Section area (m^2): w^2 (2D plane thickness = w).
    pub fn area(&self) -> f64 {
        self.w * self.w
    }

    /// Region covering the particles with x in [x0, x1], the whole section.
    pub fn region(&self, x0: f64, x1: f64) -> String {
        format!(
            "{{ min = {}, max = {} }}",
            v(self.dim, x0, 0.0),
            v(self.dim, x1, self.w)
        )
    }

    /// Region of nodes with x <= 0 (a clamp at the left end).
    pub fn left_nodes(&self) -> String {
        let m = 2.0 * self.h;
        format!(
            "{{ min = {}, max = {} }}",
            v(self.dim, -m, -m),
            v(self.dim, 0.0, self.w + m)
        )
    }

    /// The scenario text.
    pub fn toml(&self) -> String {
        let m = 2.0 * self.h;
        let plane = if self.dim == 2 {
            format!("plane = \"{}\"\nthickness = {:e}\n", self.plane, self.w)
        } else {
            String::new()
        };
        format!(
            r#"
[simulation]
dimension = {dim}
{plane}shape = "{shape}"
update = "{update}"
duration = {duration:e}
cfl = 0.5
damping = {damping:e}

[grid]
min = {gmin}
max = {gmax}
cell = {cell}

[[material]]
name = "m"
E = {e:e}
nu = {nu}
rho = {rho:e}

[[body]]
material = "m"
box = {{ min = {bmin}, max = {bmax} }}
velocity = {vel}

[output]
history_interval = {hist:e}
{extra}
"#,
            dim = self.dim,
            shape = self.shape,
            update = self.update,
            duration = self.duration,
            damping = self.damping,
            gmin = v(self.dim, -m, -m),
            gmax = v(self.dim, self.len + m, self.w + m),
            cell = v(self.dim, self.h, self.h),
            e = self.e,
            nu = self.nu,
            rho = self.rho,
            bmin = v(self.dim, 0.0, 0.0),
            bmax = v(self.dim, self.len, self.w),
            vel = v(self.dim, self.velocity, 0.0),
            hist = self.duration / 2000.0,
            extra = self.extra,
        )
    }
}

/// The world of `text` after `steps` steps run twice: on its schedule, whose closing stress
/// update is fused with the binning (checked), and keeping the stencils every step, which
/// runs that update unfused (binning waits for the next step). Returns (fused, unfused).
pub fn fused_and_unfused<D: DimSystems>(text: &str, steps: usize) -> (World<D>, World<D>) {
    let mut fused = build::<D>(&source(text)).unwrap().world;
    let mut apart = fused.clone();
    let mut fused_schedule = Schedule::for_world(&fused, None);
    let mut apart_schedule = fused_schedule.clone();
    assert!(
        fused_schedule
            .systems
            .iter()
            .any(|s| matches!(s, System::StressBin { .. }))
    );
    // Keeping the stencils runs the closing update unfused and leaves binning to `bin`.
    for _ in 0..steps {
        fused_schedule.step(&mut fused).unwrap();
        apart_schedule.step_keeping(&mut apart, true).unwrap();
    }
    (fused, apart)
}

/// A box with an initial velocity, gravity, damping, a clamp and a ramped load, and a
/// disc (sphere in 3D) in flight: most of what a step does, in a small scene.
pub fn mixed_scene(dim: usize, shape: &str, update: &str) -> String {
    let v = |a: f64, b: f64| self::v(dim, a, b);
    format!(
        r#"
[simulation]
dimension = {dim}
shape = "{shape}"
update = "{update}"
duration = 1e-5
damping = 1000.0
gravity = {g}
[grid]
min = {gmin}
max = {gmax}
cell = {cell}
[[material]]
name = "m"
E = 70e9
nu = 0.33
rho = 2700.0
[[body]]
material = "m"
box = {{ min = {bmin}, max = {bmax} }}
velocity = {vel}
[[body]]
material = "m"
{disc}
[[boundary]]
region = {{ min = {gmin}, max = {fix} }}
[[load]]
region = {{ min = {lmin}, max = {bmax} }}
force = {force}
time = {{ kind = "ramp", rise = 5e-6 }}
"#,
        g = v(0.0, -9.81),
        gmin = v(0.0, 0.0),
        gmax = v(0.064, if dim == 2 { 0.032 } else { 0.016 }),
        cell = v(0.001, 0.001),
        bmin = v(0.002, 0.002),
        bmax = v(0.04, 0.012),
        vel = v(3.0, -1.0),
        disc = if dim == 2 {
            "disc = { center = [0.05, 0.022], radius = 0.006 }"
        } else {
            "sphere = { center = [0.05, 0.008, 0.008], radius = 0.005 }"
        },
        fix = v(0.003, if dim == 2 { 0.032 } else { 0.016 }),
        lmin = v(0.038, 0.002),
        force = v(2e4, 5e3),
    )
}

/// A 2D scene on a 20 x 20 mm grid of 2 mm cells holding one square block of a soft solid
/// (E = 1 GPa, nu = 0.3, rho = 1000 kg/m^3) from (lo, lo) to (hi, hi) (m), run for
/// `duration` (s); `extra` follows (loads, cracks, output).
pub fn block_2d(duration: f64, lo: f64, hi: f64, extra: &str) -> String {
    format!(
        r#"
[simulation]
dimension = 2
duration = {duration:e}
[grid]
min = [0.0, 0.0]
max = [0.02, 0.02]
cell = [0.002, 0.002]
[[material]]
name = "m"
E = 1e9
nu = 0.3
rho = 1000.0
[[body]]
material = "m"
box = {{ min = [{lo:e}, {lo:e}], max = [{hi:e}, {hi:e}] }}
{extra}"#
    )
}

/// For [`strip_2d`]: a bar 28 x 8 mm between a support at x = 2 mm and a grip at 30 mm,
/// both holding x only (each every node from its end of the bar outwards), the grip moved
/// at 0.1 m/s under a table that rises over 10 us, holds 10 us and falls back over 10 us
/// (2 um in all); probes `support` and `grip` read their reactions along x.
pub const GRIPPED_BAR: &str = r#"
[[body]]
material = "m"
box = { min = [0.002, 0.002], max = [0.03, 0.01] }
[[boundary]]
region = { min = [0.0, 0.0], max = [0.002, 0.012] }
fix = ["x"]
[[boundary]]
region = { min = [0.03, 0.0], max = [0.04, 0.012] }
fix = ["x"]
velocity = [0.1, 0.0]
time = { kind = "table", points = [[0.0, 0.0], [1e-5, 1.0], [2e-5, 1.0], [3e-5, 0.0]] }
[[probe]]
name = "support"
region = { min = [0.0, 0.0], max = [0.002, 0.012] }
quantity = "reaction"
component = "x"
[[probe]]
name = "grip"
region = { min = [0.03, 0.0], max = [0.04, 0.012] }
quantity = "reaction"
component = "x"
"#;

/// A 2D scene on a 40 x 12 mm grid of 1 mm cells with an aluminium named "m" (E = 70 GPa,
/// nu = 0.3, rho = 2700 kg/m^3), run for `duration` (s); `simulation` adds keys to
/// `[simulation]` (one per line) and `rest` follows the material (bodies, cracks).
pub fn strip_2d(simulation: &str, duration: f64, rest: &str) -> String {
    format!(
        r#"
[simulation]
dimension = 2
{simulation}
duration = {duration:e}
[grid]
min = [0.0, 0.0]
max = [0.04, 0.012]
cell = [0.001, 0.001]
[[material]]
name = "m"
E = 70e9
nu = 0.3
rho = 2700.0
{rest}"#
    )
}

/// An 8 x 16 mm plate with a 2 mm edge crack under a ramped tension; `growth` is the body
/// of its `[crack.growth]` table and `duration` the run's length (s).
pub fn edge_plate(growth: &str, duration: f64) -> String {
    format!(
        r#"name = "edge_growth"
[simulation]
dimension = 2
duration = {duration:e}
cfl = 0.5
damping = 4.0e5
[grid]
min = [-0.0015, -0.00875]
max = [0.0095, 0.00875]
cell = [0.0005, 0.0005]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "steel"
box = {{ min = [0.0, -0.008], max = [0.008, 0.008] }}
[[crack]]
name = "edge"
line = {{ start = [-0.0005, 0.0], end = [0.002, 0.0] }}
[crack.growth]
{growth}
[[load]]
region = {{ min = [0.0, 0.0077], max = [0.008, 0.008] }}
force = [0.0, 8.0e5]
time = {{ kind = "ramp", rise = 4.0e-6 }}
[[load]]
region = {{ min = [0.0, -0.008], max = [0.008, -0.0077] }}
force = [0.0, -8.0e5]
time = {{ kind = "ramp", rise = 4.0e-6 }}
[fracture]
contour = 2
[output]
history_interval = 1.0e-6
"#
    )
}

/// A 12 mm steel cube with a penny crack of radius 3 mm at its centre, normal to y, under
/// a ramped tension `force` (N) on its top and bottom particle layers; `growth` is the
/// body of the crack's `[crack.growth]` table and `duration` the run's length (s). J and
/// K are measured on tubes of two cells when `force` is not zero.
pub fn penny_block(growth: &str, force: f64, duration: f64) -> String {
    let fracture = if force != 0.0 {
        "[fracture]\ndomain = 2\n"
    } else {
        ""
    };
    format!(
        r#"name = "penny_growth"
[simulation]
dimension = 3
shape = "ugimp"
update = "usavg"
duration = {duration:e}
cfl = 0.5
damping = 6.0e5
[grid]
min = [-0.002, -0.002, -0.002]
max = [0.014, 0.014, 0.014]
cell = [0.001, 0.001, 0.001]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 8000.0
[[body]]
material = "steel"
box = {{ min = [0.0, 0.0, 0.0], max = [0.012, 0.012, 0.012] }}
[[crack]]
name = "penny"
penny = {{ center = [0.006, 0.006, 0.006], normal = [0.0, 1.0, 0.0], radius = 0.003 }}
[crack.growth]
{growth}
[[load]]
region = {{ min = [0.0, 0.0115, 0.0], max = [0.012, 0.012, 0.012] }}
force = [0.0, {force:e}, 0.0]
time = {{ kind = "ramp", rise = 2.0e-6 }}
[[load]]
region = {{ min = [0.0, 0.0, 0.0], max = [0.012, 0.0005, 0.012] }}
force = [0.0, {neg:e}, 0.0]
time = {{ kind = "ramp", rise = 2.0e-6 }}
{fracture}[output]
history_interval = 1.0e-6
"#,
        neg = -force
    )
}

/// A fatigue law for [`penny_block`]: Paris growth by a quarter cell every
/// microsecond (12 steps) from the check at 4.1 us on.
pub const PENNY_FATIGUE: &str = r#"initiation = "time"
at = 3.5e-6
extension = 2.5e-4
interval = 1.0e-6
paris = { C = 1.0e-29, m = 3.0 }"#;

/// A fatigue law for [`edge_plate`]: Paris growth by a cell every 4 us from 10 us on.
pub const PARIS_GROWTH: &str = r#"initiation = "time"
at = 1.0e-5
extension = 5.0e-4
interval = 4.0e-6
paris = { C = 1.0e-29, m = 3.0, R = 0.25 }"#;

/// `text` with its first material made von Mises plastic with `hardening` (e.g. "n = 5" or
/// "H = 1e9") and yield stress `sigma_y` (Pa).
pub fn plastic(text: &str, sigma_y: f64, hardening: &str) -> String {
    let at = text.find("\nrho = ").expect("a material") + 1;
    let end = at + text[at..].find('\n').expect("a line") + 1;
    format!(
        "{}model = \"j2\"\nsigma_y = {sigma_y:e}\n{hardening}\n{}",
        &text[..end],
        &text[end..]
    )
}

/// K_I of a centre crack of half-length `a` in a plate of half-width `b` under remote
/// tension `s`: Tada's form of Feddersen's formula (scenarios/reference/README.md), good to
/// 0.1 %.
pub fn feddersen(s: f64, a: f64, b: f64) -> f64 {
    let (r, pi) = (a / b, std::f64::consts::PI);
    s * (pi * a).sqrt()
        * (1.0 - 0.025 * r * r + 0.06 * r.powi(4))
        * (1.0 / (pi * a / (2.0 * b)).cos()).sqrt()
}

/// A `[[load]]` of force `force` (N) on the particles in the box `min`-`max`, rising in
/// proportion to the time from 0 to 1 s.
pub fn ramped_load<const N: usize>(min: [f64; N], max: [f64; N], force: [f64; N]) -> String {
    format!(
        "[[load]]\nregion = {{ min = {min:?}, max = {max:?} }}\nforce = {force:?}\n\
         time = {{ kind = \"table\", points = [[0.0, 0.0], [1.0, 1.0]] }}\n"
    )
}

/// A 60 mm steel plate (plane strain, cells of `cell` m) solved static in `steps` load
/// steps of a load rising in proportion to sigma_yy = -100 MPa and tau_xy = 50 MPa on its
/// edges (each edge's particle layer), with a crack of half-length `half` m on its
/// mid-plane, half a cell off the node rows, under contact law `law` (None: no crack), the
/// steel's keys extended by `model`.
pub fn sheared_plate(cell: f64, half: f64, law: Option<&str>, steps: usize, model: &str) -> String {
    let crack = law.map_or(String::new(), |law| {
        format!(
            "[[crack]]\nname = \"shut\"\nline = {{ start = [{}, 0.0], end = [{half}, 0.0] }}\n\
             contact = {law}\n",
            -half
        )
    });
    let edge = ramped_load::<2>;
    // Edge tractions (t = sigma . n) times the 60 mm edges, unit thickness.
    let (a, b) = (0.03, 0.03 - 0.5 * cell);
    let loads = [
        edge([-a, b], [a, a], [3.0e6, -6.0e6]),
        edge([-a, -a], [a, -b], [-3.0e6, 6.0e6]),
        edge([b, -a], [a, a], [0.0, 3.0e6]),
        edge([-a, -a], [-b, a], [0.0, -3.0e6]),
    ]
    .concat();
    let g = a + 2.0 * cell;
    format!(
        r#"
[simulation]
dimension = 2
plane = "strain"
solver = "static"
duration = 1.0
load_steps = {steps}
[grid]
min = [{}, {}]
max = [{g}, {g}]
cell = [{cell}, {cell}]
anchor = {{ point = [0.0, 0.0], offset = [0.0, 0.5] }}
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
{model}
[[body]]
material = "steel"
box = {{ min = [-0.03, -0.03], max = [0.03, 0.03] }}
{loads}
{crack}
"#,
        -g, -g
    )
}

/// A 30 mm steel cube held at its base, its top loaded by `force` (N) ramped over 0.1 ms,
/// with the elliptical crack `ellipse` (its TOML table) under Coulomb friction `mu`, 2 mm
/// cells, solved static in `load_steps`: the random scenes of docs/static-solver.md
/// (tests/static_solver.rs; tests/mpi.rs on ranks).
pub fn pressed_cube(force: [f64; 3], ellipse: &str, mu: f64, load_steps: usize) -> String {
    let dt = 1.0e-4 / load_steps as f64;
    format!(
        r#"
[simulation]
dimension = 3
solver = "static"
load_steps = {load_steps}
duration = 1.0e-4
[grid]
min = [-0.004, -0.004, -0.004]
max = [0.034, 0.034, 0.034]
cell = [0.002, 0.002, 0.002]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 8000.0
[[body]]
material = "steel"
box = {{ min = [0.0, 0.0, 0.0], max = [0.03, 0.03, 0.03] }}
[[boundary]]
region = {{ min = [-0.004, -0.004, -0.004], max = [0.034, 0.0, 0.034] }}
[[load]]
region = {{ min = [0.0, 0.0295, 0.0], max = [0.03, 0.03, 0.03] }}
force = {force:?}
time = {{ kind = "ramp", rise = 1.0e-4 }}
[[crack]]
name = "c"
ellipse = {ellipse}
contact = {{ law = "friction", friction = {mu} }}
[output]
interval = {dt}
history_interval = {dt}
"#
    )
}

/// Lame's thick shell (bore a = 0.1 m, outside b = 0.2 m) under a bore pressure of 100 MPa
/// rising under the table `points` (E = 200 GPa, nu = `nu`): in 2D a quarter of a cylinder
/// in plane strain on 5 mm cells, in 3D an eighth of a sphere on 10 mm cells (29,318
/// particles), on symmetry planes; `simulation` adds its lines to `[simulation]`. Probes
/// `axis` and `diagonal` read the x displacement at r = 0.15 m next to the x axis and on
/// the diagonal.
pub fn pressed_shell(dim: usize, nu: f64, simulation: &str, points: &str) -> String {
    let (plane, cell, body, reach, axis, diagonal) = if dim == 2 {
        (
            "plane = \"strain\"",
            0.005,
            "disc = { center = [0.0, 0.0], radius = 0.2, inner_radius = 0.1 }\n\
             clip = { polygon = [[0.0, 0.0], [0.21, 0.0], [0.21, 0.21], [0.0, 0.21]] }",
            0.1025,
            "center = [0.15, 0.0025], radius = 0.003",
            "center = [0.10607, 0.10607], radius = 0.004",
        )
    } else {
        (
            "",
            0.01,
            "sphere = { center = [0.0, 0.0, 0.0], radius = 0.2, inner_radius = 0.1 }\n\
             clip = { min = [0.0, 0.0, 0.0], max = [0.21, 0.21, 0.21] }",
            0.105,
            "center = [0.15, 0.0025, 0.0025], radius = 0.006",
            "center = [0.0866, 0.0866, 0.0866], radius = 0.006",
        )
    };
    let planes: String = ["x", "y", "z"][..dim]
        .iter()
        .map(|a| format!("[[boundary]]\nplane = {{ axis = \"{a}\", at = 0.0 }}\n"))
        .collect();
    let o = v(dim, 0.0, 0.0);
    format!(
        r#"
[simulation]
dimension = {dim}
{plane}
{simulation}
[grid]
min = {}
max = {}
cell = {}
[[material]]
name = "m"
E = 200e9
nu = {nu}
rho = 7800.0
[[body]]
material = "m"
{body}
{planes}
[[load]]
region = {{ center = {o}, radius = {reach} }}
pressure = {{ value = 100e6, center = {o}, face = "inner" }}
time = {{ kind = "table", points = {points} }}
[[probe]]
name = "axis"
region = {{ {axis} }}
quantity = "displacement"
component = "x"
[[probe]]
name = "diagonal"
region = {{ {diagonal} }}
quantity = "displacement"
component = "x"
"#,
        v(dim, -0.01, -0.01),
        v(dim, 0.21, 0.21),
        v(dim, cell, cell),
    )
}
