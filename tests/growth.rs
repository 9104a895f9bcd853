//! Crack growth: the fatigue bookkeeping against the Paris law recomputed from the K the
//! run read, tips that reach a surface or leave the grid, and bitwise determinism over
//! thread counts.

mod common;

use common::{PARIS_GROWTH, PENNY_FATIGUE, edge_plate, source};
use fissure::app::run::{Outcome, RunOptions, run, step_count};
use fissure::base::dim::D3;
use fissure::io::output::summary::Status;
use fissure::io::scenario::build;
use fissure::physics::growth::GrowthRow;
use fissure::pipeline::schedule::Schedule;
use fissure::store::world::World;
use glam::DVec3;

fn run_with(text: &str, threads: usize) -> Outcome {
    let opts = RunOptions {
        threads,
        ..RunOptions::default()
    };
    run(&source(text), &opts).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Each fatigue row's cycles are the last row's plus the trapezoidal rule on the Paris
/// rate C ((1 - R) K_I)^m at the two lengths, recomputed here from the K_I the rows
/// record (mode I: no kink, Delta K_eq = (1 - R) K_I, Belytschko et al. 1995, Eq. 40).
#[test]
fn fatigue_cycles_follow_the_paris_law() {
    let out = run_with(&edge_plate(PARIS_GROWTH, 2.8e-5), 2);
    let rows: Vec<&GrowthRow> = out.history.growth.iter().collect();
    assert!(rows.len() >= 4, "{} rows", rows.len());
    let rate = |g: &GrowthRow| 1.0e-29 * (0.75 * g.k[0]).powi(3);
    assert_eq!(rows[0].fatigue[1], 0.0);
    for w in rows.windows(2) {
        let (a, b) = (w[0], w[1]);
        assert!((b.fatigue[0] - 0.75 * b.k[0]).abs() <= 1e-9 * b.fatigue[0]);
        assert!(
            b.kink.abs() < 1e-3,
            "a mode I crack grows straight: {}",
            b.kink
        );
        let da = b.grown - a.grown;
        assert!((da - 5.0e-4).abs() < 1e-12, "one extension per check: {da}");
        let expected = a.fatigue[1] + 0.5 * da * (1.0 / rate(a) + 1.0 / rate(b));
        assert!(
            (b.fatigue[1] - expected).abs() <= 1e-9 * expected,
            "{} against {expected}",
            b.fatigue[1]
        );
        assert!(b.k[0] > a.k[0], "K_I grows with the crack");
    }
    let g = &out.summary.growth[0];
    assert_eq!((g.crack.as_str(), g.tip.as_str()), ("edge", "end"));
    assert!(g.stopped.is_none());
    assert!((g.grown - 5.0e-4 * rows.len() as f64).abs() < 1e-12);
    // fracture.csv's crack length grows by the length grown (the polyline also stretches
    // with the body, by far less than 1 % of that).
    let tips = &out.history.fracture;
    let (first, last) = (tips.first().unwrap(), tips.last().unwrap());
    assert!((first.length - 2.5e-3).abs() < 1e-9, "{}", first.length);
    let grown = last.length - first.length;
    assert!(
        (grown - g.grown).abs() < 0.01 * g.grown,
        "{grown} against {}",
        g.grown
    );
}

/// Two edge cracks of different depths in one plate under one cyclic load: at every check
/// the deeper one grows a whole extension and the shallower one the share of it that the
/// ratio of their Paris rates (from the Delta K_eq each row records) gives, a new segment
/// each, so that both see the same load cycles. Each tip sums its cycles by the
/// trapezoidal rule on its own rates; the counts agree to the order of the extension (a
/// quarter of the depth in this small plate, where they part by 10 %).
#[test]
fn two_fatigue_cracks_grow_by_their_rates() {
    let right = format!(
        "[[crack]]\nname = \"right\"\nline = {{ start = [0.0085, -0.002], end = [0.0065, -0.002] }}\n\
         [crack.growth]\n{PARIS_GROWTH}\n[[load]]"
    );
    let text = edge_plate(PARIS_GROWTH, 2.8e-5)
        .replace("[0.002, 0.0] }", "[0.002, 0.002] }")
        .replace("[-0.0005, 0.0]", "[-0.0005, 0.002]")
        .replacen("[[load]]", &right, 1);
    let out = run_with(&text, 2);
    let rate = |g: &GrowthRow| 1.0e-29 * g.fatigue[0].powi(3);
    let rows = |crack: u32| -> Vec<&GrowthRow> {
        out.history
            .growth
            .iter()
            .filter(|r| r.crack == crack)
            .collect()
    };
    let (deep, shallow) = (rows(0), rows(1));
    assert!(
        deep.len() >= 4 && deep.len() == shallow.len(),
        "{} and {}",
        deep.len(),
        shallow.len()
    );
    for k in 0..deep.len() - 1 {
        let (d, s) = (deep[k], shallow[k]);
        assert_eq!(d.step, s.step, "both tips are checked together");
        assert!(rate(s) < rate(d), "the shallower crack is slower");
        let share = 5.0e-4 * rate(s) / rate(d);
        let grown = (deep[k + 1].grown - d.grown, shallow[k + 1].grown - s.grown);
        assert!((grown.0 - 5.0e-4).abs() < 1e-12, "{grown:?}");
        assert!((grown.1 - share).abs() < 1e-12, "{grown:?} against {share}");
        for r in [&deep, &shallow] {
            let (a, b) = (r[k], r[k + 1]);
            let da = b.grown - a.grown;
            let expected = a.fatigue[1] + 0.5 * da * (1.0 / rate(a) + 1.0 / rate(b));
            assert!((b.fatigue[1] - expected).abs() <= 1e-9 * expected);
        }
    }
}

/// A tip running straight across the plate stops at the far surface, says so, and grows
/// no more; the crack then cuts the body through.
#[test]
fn a_tip_stops_at_the_free_surface() {
    let text = edge_plate(
        "initiation = \"time\"\nat = 2.0e-6\ndirection = \"straight\"\nspeed = 2000.0",
        8.0e-6,
    );
    let out = run_with(&text, 2);
    assert_eq!(out.summary.status, Status::Completed);
    let g = &out.summary.growth[0];
    assert_eq!(g.stopped.as_deref(), Some("reached the free surface"));
    assert!(
        g.x[0] > 0.008 && g.x[0] < 0.0095,
        "a cell past the surface: {}",
        g.x[0]
    );
    assert!(g.x[1].abs() < 1e-12, "straight on: {}", g.x[1]);
    // fracture.csv's tip speed is the set speed while the tip runs, 0 before it starts and
    // once it has stopped.
    let speeds: Vec<f64> = out.history.fracture.iter().map(|t| t.speed).collect();
    let running = |v: f64| (v - 2000.0).abs() < 1e-6;
    assert!(speeds.iter().all(|&v| v == 0.0 || running(v)), "{speeds:?}");
    assert!(
        speeds[0] == 0.0 && running(speeds[speeds.len() / 2]),
        "{speeds:?}"
    );
    assert_eq!(*speeds.last().unwrap(), 0.0, "stopped");
}

/// A tip set running under tension and shear turns once, by the hoop angle of the K it
/// reads at rest, and then keeps that heading; its K is not reported until it has run
/// three cells (1.5 mm here), and is from then on.
#[test]
fn a_running_tip_turns_once_and_reads_k_after_three_cells() {
    let text = edge_plate(
        "initiation = \"time\"\nat = 6.0e-6\ndirection = \"hoop\"\nspeed = 1500.0",
        9.0e-6,
    )
    .replace("force = [0.0, 8.0e5]", "force = [4.0e5, 8.0e5]")
    .replace("force = [0.0, -8.0e5]", "force = [-4.0e5, -8.0e5]")
    .replace("history_interval = 1.0e-6", "history_interval = 1.0e-7");
    let out = run_with(&text, 2);
    let rows = &out.history.growth;
    assert!(rows.len() > 4, "{} segments", rows.len());
    assert!(
        rows[0].kink.abs() > 0.1,
        "a turn at the start: {}",
        rows[0].kink
    );
    assert!(
        rows.iter().all(|r| r.heading == rows[0].heading),
        "one heading"
    );
    let length0 = out.history.fracture[0].length;
    let (mut early, mut late) = (0, 0);
    for t in out.history.fracture.iter().filter(|t| t.speed > 0.0) {
        if t.length - length0 < 1.5e-3 - 1e-9 {
            assert!(t.k[0].is_nan(), "too few faces at {}", t.time);
            early += 1;
        } else {
            assert!(t.k[0].is_finite() && t.k[0] > 0.0, "K at {}", t.time);
            late += 1;
        }
    }
    assert!(early > 0 && late > 0, "{early} {late}");
}

/// A tip carried past the surface beyond the grid's edge makes the run unstable, with a
/// message that names the crack and where its tip went, and the last good snapshot.
#[test]
fn growth_out_of_the_grid_stops_the_run() {
    let text = edge_plate(
        "initiation = \"time\"\nat = 2.0e-6\ndirection = \"straight\"\nspeed = 2000.0",
        8.0e-6,
    )
    .replace("max = [0.0095, 0.00875]", "max = [0.0085, 0.00875]")
        + "[checkpoint]\nevery_steps = 20\n";
    let dir = std::env::temp_dir().join(format!("fissure-grow-{}-grid", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    let opts = RunOptions {
        out: Some(dir.clone()),
        ..RunOptions::default()
    };
    let err = run(&source(&text), &opts)
        .expect_err("must stop")
        .to_string();
    assert!(err.contains("crack `edge` grew out of the grid"), "{err}");
    assert!(err.contains("last good snapshot"), "{err}");
    std::fs::remove_dir_all(dir).ok();
}

/// Growth, with the K it reads and the cycles it counts, is bitwise the same on 1, 2 and
/// 3 threads.
#[test]
fn growth_is_identical_on_one_two_and_three_threads() {
    let one = same_on_one_two_and_three_threads(&edge_plate(PARIS_GROWTH, 2.0e-5));
    assert!(!one.history.growth.is_empty());
}

/// Runs `text` on 1, 2 and 3 threads, asserts that the growth and fracture rows are
/// bitwise the same, and returns the one-thread run.
fn same_on_one_two_and_three_threads(text: &str) -> Outcome {
    let bits = |o: &Outcome| -> Vec<u64> {
        (o.history.growth.iter())
            .flat_map(|g| g.values())
            .chain(o.history.fracture.iter().flat_map(|t| t.values()))
            .map(f64::to_bits)
            .collect()
    };
    let one = run_with(text, 1);
    for threads in [2, 3] {
        assert!(
            bits(&one) == bits(&run_with(text, threads)),
            "{threads} threads"
        );
    }
    one
}

/// growth.csv holds one row per new segment, as the history does, with the cycles in its
/// last column, and cycles.csv the length grown against cycles; growth.png draws the
/// path.
#[test]
fn growth_outputs_are_written() {
    let dir = std::env::temp_dir().join(format!("fissure-grow-{}-out", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    let opts = RunOptions {
        out: Some(dir.clone()),
        ..RunOptions::default()
    };
    let out = run(&source(&edge_plate(PARIS_GROWTH, 2.0e-5)), &opts).unwrap();
    let csv = std::fs::read_to_string(dir.join("growth.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].ends_with("dKeq,cycles"), "{}", lines[0]);
    assert_eq!(lines.len() - 1, out.history.growth.len());
    for (line, row) in lines[1..].iter().zip(&out.history.growth) {
        let cycles: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
        assert!((cycles - row.fatigue[1]).abs() <= 1e-8 * row.fatigue[1].max(1.0));
    }
    // cycles.csv: the fatigue rows alone, length grown against cycles.
    let cycles = std::fs::read_to_string(dir.join("cycles.csv")).unwrap();
    let lines: Vec<&str> = cycles.lines().collect();
    assert_eq!(lines[0], "step,time,crack,tip,grown,dKeq,cycles");
    assert_eq!(lines.len() - 1, out.history.growth.len());
    for (line, row) in lines[1..].iter().zip(&out.history.growth) {
        let v: Vec<f64> = line
            .split(',')
            .skip(4)
            .map(|x| x.parse().unwrap())
            .collect();
        assert!((v[0] - row.grown).abs() <= 1e-8 * row.grown.max(1e-3));
        assert!((v[2] - row.fatigue[1]).abs() <= 1e-8 * row.fatigue[1].max(1.0));
    }
    let png = std::fs::read(dir.join("growth.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"), "growth.png is a PNG");
    std::fs::remove_dir_all(dir).ok();
}

/// A 3D front set growing by the clock with no load: at every check each vertex of the
/// penny's front moves a whole extension along its radius (the frame's x1 axis of a
/// regular polygon), so the crack is the polygon of the same vertices at the grown radius
/// (area N/2 r^2 sin(2 pi / N)), the front keeps its vertices, and growth.csv's mean
/// advance counts the checks.
#[test]
fn a_3d_front_grows_in_its_plane_and_stays_round() {
    let growth = "initiation = \"time\"\nat = 1.0e-6\nextension = 2.5e-4\ninterval = 1.0e-6";
    let text = common::penny_block(growth, 0.0, 3.05e-6);
    let world: World<D3> = common::final_world(&text, 2);
    let out = run_with(&text, 2);
    let rows = &out.history.growth;
    assert_eq!(rows.len(), 3, "checks at 1, 2 and 3 us");
    for (k, g) in rows.iter().enumerate() {
        assert!((g.grown - 2.5e-4 * k as f64).abs() < 1e-15, "{}", g.grown);
    }
    let cracks = world.cracks.as_ref().unwrap();
    let front = &cracks.topology.fronts()[0].vertices;
    let n = front.len() as f64;
    let centre = DVec3::splat(0.006);
    let radius = 0.003 + 3.0 * 2.5e-4;
    for &v in front {
        let d = cracks.geometry.x[v as usize] - centre;
        assert!(
            d.y.abs() < 1e-12 && (d.length() - radius).abs() < 1e-12,
            "{d}"
        );
    }
    let x = &cracks.geometry.x;
    let area: f64 = (cracks.topology.elems().iter())
        .map(|t| {
            let [a, b, c] = t.map(|k| x[k as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    let exact = 0.5 * n * radius * radius * (std::f64::consts::TAU / n).sin();
    assert!(
        (area - exact).abs() < 1e-12 * exact,
        "{area} against {exact}"
    );
}

/// Fatigue along a 3D front, with the K it reads and the cycles it counts, is bitwise the
/// same on 1, 2 and 3 threads; the front grows at every check.
#[test]
fn front_growth_is_identical_on_one_two_and_three_threads() {
    let text = common::penny_block(PENNY_FATIGUE, 7.2e3, 6.3e-6);
    let one = same_on_one_two_and_three_threads(&text);
    let rows = &one.history.growth;
    assert_eq!(rows.len(), 3, "checks at 4.1, 5.2 and 6.2 us");
    assert!(rows.windows(2).all(|w| w[1].fatigue[1] > w[0].fatigue[1]));
}

/// A 3D front set growing by the clock a cell per check reaches the cube's faces (3 mm
/// from the penny's rim along the axes): it stops as a whole at the check whose move would
/// carry a vertex out of the body, that move not taken, and the summary says so.
#[test]
fn a_3d_front_stops_at_the_free_surface() {
    let growth = "initiation = \"time\"\nat = 1.0e-6\nextension = 1.0e-3\ninterval = 1.0e-6";
    let out = run_with(&common::penny_block(growth, 0.0, 6.05e-6), 2);
    let g = &out.summary.growth[0];
    assert_eq!((g.crack.as_str(), g.tip.as_str()), ("penny", "front"));
    assert_eq!(g.stopped.as_deref(), Some("reached the free surface"));
    // Three whole cells grown, to a radius of 6 mm (the vertices on the axes on the
    // faces, a quarter cell from the outer particles); the fourth would carry them a cell
    // past.
    assert!((g.grown - 3.0e-3).abs() < 1e-12, "{}", g.grown);
}

/// A 3D front under the energy criterion: with G_c far below the J it reads every vertex
/// holds, so the front advances a whole extension at each check from the first; with G_c
/// far above, it never starts.
#[test]
fn a_3d_front_grows_where_j_reaches_gc() {
    let law = |g_c: f64| {
        format!("initiation = \"energy\"\nGc = {g_c:e}\nextension = 2.5e-4\ninterval = 1.0e-6")
    };
    let out = run_with(&common::penny_block(&law(1.0e-3), 7.2e3, 6.3e-6), 2);
    let rows = &out.history.growth;
    assert!(rows.len() >= 3, "{} checks grew", rows.len());
    for (k, g) in rows.iter().enumerate() {
        assert!((g.grown - 2.5e-4 * k as f64).abs() < 1e-15, "{}", g.grown);
    }
    let out = run_with(&common::penny_block(&law(1.0e9), 7.2e3, 6.3e-6), 2);
    assert!(out.history.growth.is_empty());
    assert_eq!(out.summary.growth[0].started, None);
}

/// The world at the end of `text`'s run with the scene's fracture plan, so that growth
/// reads K as the launcher's runs do.
fn grown_world(text: &str) -> World<D3> {
    let scene = build::<D3>(&source(text)).unwrap_or_else(|e| panic!("{e}"));
    let mut world = scene.world;
    let mut schedule = Schedule::for_world(&world, scene.fracture.clone());
    let steps = step_count(scene.duration, world.settings.dt);
    while world.step < steps {
        schedule.step(&mut world).unwrap_or_else(|e| panic!("{e}"));
    }
    world
}

/// Under the hoop direction a 3D front turns by the hoop-stress angle of its own K_I and
/// K_II. A penny normal to the load (half a cell off the node plane; no K_II) keeps its
/// plane, to a hundredth of the extension. Tilted 45 degrees, the front turns most where
/// K_II is largest, by about the 55.5 degrees of the infinite body's K_II / K_I there (this
/// small, coarse block reads within 5 degrees), and towards the plane normal to the load:
/// the vertex that lay along (-1, 1, 0), where K_II is largest, moves within 20 degrees of
/// the horizontal (straight on it would climb at the crack's 45).
#[test]
fn a_3d_front_turns_by_the_hoop_stress() {
    let growth = "initiation = \"time\"\nat = 3.5e-6\ndirection = \"hoop\"\nextension = 2.5e-4\n\
                  interval = 1.0e-6";
    let text = common::penny_block(growth, 7.2e3, 4.3e-6);
    let flat = text.replace(
        "center = [0.006, 0.006, 0.006]",
        "center = [0.006, 0.0065, 0.006]",
    );
    let row = run_with(&flat, 2).history.growth[0];
    assert!(row.k[0] > 0.0 && row.kink.to_degrees() < 1.0, "{row:?}");
    let world = grown_world(&flat);
    let cracks = world.cracks.as_ref().unwrap();
    for &v in &cracks.topology.fronts()[0].vertices {
        let y = cracks.geometry.x[v as usize].y;
        assert!(
            (y - 0.0065).abs() < 2.5e-6,
            "a vertex left the plane: y = {y}"
        );
    }
    let tilted = text.replace("normal = [0.0, 1.0, 0.0]", "normal = [1.0, 1.0, 0.0]");
    let out = run_with(&tilted, 2);
    let kink = out.history.growth[0].kink.to_degrees();
    assert!((kink - 55.5).abs() < 5.0, "largest turn {kink} degrees");
    // The front keeps its vertices: follow the one along (-1, 1, 0) over the check.
    let along = DVec3::new(-1.0, 1.0, 0.0).normalize();
    let before = grown_world(&tilted.replace("duration = 4.3e-6", "duration = 3.9e-6"));
    let c = before.cracks.as_ref().unwrap();
    let offset = |v: u32| (c.geometry.x[v as usize] - DVec3::splat(0.006)).dot(along);
    let v = (c.topology.fronts()[0].vertices.iter().copied())
        .max_by(|&a, &b| offset(a).total_cmp(&offset(b)))
        .unwrap() as usize;
    let after = grown_world(&tilted);
    let moved = after.cracks.as_ref().unwrap().geometry.x[v] - c.geometry.x[v];
    let slope = (moved.y / moved.x.hypot(moved.z)).atan().to_degrees();
    assert!(
        slope.abs() < 20.0,
        "the turn closes towards the horizontal: {moved}"
    );
}
