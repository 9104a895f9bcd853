//! `sweep`: every combination runs once and lands in sweep.csv; a sweep stopped part-way
//! runs only what is missing; bad keys, values and oversized sweeps are refused before
//! the first run.

mod common;

use fissure::app::sweep::{Swept, Vary, sweep};
use std::path::{Path, PathBuf};

/// A fresh folder under the system temp folder, and a scenario file in it: the block of
/// `common::block_2d` moving at 1 m/s with an energy-balance expect, so each row carries
/// an error.
fn setup(name: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("fissure-sweep-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    let text = common::block_2d(
        2e-5,
        0.006,
        0.014,
        "velocity = [1.0, 0.0]\n[[expect]]\nquantity = \"energy_drift\"\nreference = 0.0\nsource = \"balance\"\n\
         tolerance = 0.01\n",
    );
    let file = dir.join("block.toml");
    std::fs::write(&file, format!("name = \"block\"\n{text}")).unwrap();
    (dir, file)
}

fn vary(args: &[&str]) -> Vec<Vary> {
    args.iter().map(|a| Vary::parse(a).unwrap()).collect()
}

/// Runs the sweep, returning the progress lines (index and whether it ran).
fn go(file: &Path, v: &[Vary], out: &Path) -> Vec<(usize, bool)> {
    let mut seen = Vec::new();
    let swept = sweep(file, v, 1, out, false, None, |r| {
        seen.push((r.index.0, r.summary.is_some()))
    })
    .unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(swept, Swept::Complete);
    seen
}

/// Two cell sizes by two shape functions: four rows; the finer cells hold four times the
/// particles; dropping the last row and sweeping again runs that one only.
#[test]
fn every_combination_runs_once_and_a_stopped_sweep_resumes() {
    let (dir, file) = setup("grid");
    let out = dir.join("out");
    let v = vary(&[
        "grid.cell=[2e-3, 2e-3],[1e-3, 1e-3]",
        "simulation.shape=linear,ugimp",
    ]);
    let seen = go(&file, &v, &out);
    assert_eq!(seen, vec![(1, true), (2, true), (3, true), (4, true)]);
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 5, "{csv}");
    assert!(lines[0].starts_with("grid.cell,simulation.shape,status,particles"));
    assert!(lines[0].ends_with("energy_drift value,energy_drift error,energy_drift pass"));
    let particles = |l: &str| -> usize {
        let after = l.rsplit_once("\",").unwrap().1;
        after.split(',').nth(2).unwrap().parse().unwrap()
    };
    assert_eq!(particles(lines[3]), 4 * particles(lines[1]));
    assert!(lines[4].starts_with("\"[1e-3, 1e-3]\",ugimp,completed,"));
    let png = std::fs::read(out.join("sweep_0.png")).unwrap();
    assert!(
        png.starts_with(b"\x89PNG"),
        "sweep_0.png is the error-against-cost plot"
    );
    let png = std::fs::read(out.join("sweep_0_cell.png")).unwrap();
    assert!(
        png.starts_with(b"\x89PNG"),
        "sweep_0_cell.png: error against cell size"
    );
    std::fs::write(out.join("sweep.csv"), lines[..4].join("\n") + "\n").unwrap();
    let seen = go(&file, &v, &out);
    assert_eq!(seen, vec![(1, false), (2, false), (3, false), (4, true)]);
    let again = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(again.lines().count(), 5);
    // The same run again: the same figures but for its timing.
    let untimed = |l: &str| -> Vec<String> {
        // After the quoted cell size: shape, status, particles, nodes, steps, two timings.
        let f: Vec<String> = l
            .rsplit_once("\",")
            .unwrap()
            .1
            .split(',')
            .map(String::from)
            .collect();
        [&f[..5], &f[7..]].concat()
    };
    assert_eq!(untimed(again.lines().last().unwrap()), untimed(lines[4]));
    assert!(!lines[4].contains("NaN"), "{}", lines[4]);
    std::fs::remove_dir_all(dir).ok();
}

/// A stop asked for while a sweep runs (here as its first run reports) ends it after that
/// run: sweep.csv holds the header and that run's row, whole; the next run, which sees the
/// stop at its start, leaves none; sweeping again runs only what is missing.
#[test]
fn a_stopped_sweep_keeps_whole_rows_and_resumes() {
    let (dir, file) = setup("stop");
    let out = dir.join("out");
    let v = vary(&["simulation.shape=linear,ugimp,bspline"]);
    let stop = fissure::app::run::stop::StopFlag::default();
    let flag = stop.clone();
    let mut ran = Vec::new();
    let swept = sweep(&file, &v, 1, &out, false, Some(stop), |r| {
        ran.push(r.index.0);
        flag.ask();
    })
    .unwrap();
    assert_eq!((swept, ran), (Swept::Stopped, vec![1]));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 2, "{csv}");
    assert!(csv.ends_with('\n') && csv.lines().nth(1).unwrap().starts_with("linear,completed"));
    let seen = go(&file, &v, &out);
    assert_eq!(seen, vec![(1, false), (2, true), (3, true)]);
    std::fs::remove_dir_all(dir).ok();
}

/// A bad key or value is named before any run (no sweep.csv), as are a repeated key, a
/// sweep of more than 1,000 runs without `yes` and one past 10,000 runs even with it; a
/// malformed --vary is refused.
#[test]
fn bad_sweeps_are_refused_before_the_first_run() {
    let (dir, file) = setup("bad");
    let out = dir.join("out");
    let refused = |v: &[Vary], yes: bool| -> String {
        let e = sweep(&file, v, 1, &out, yes, None, |_| panic!("no run may start"))
            .expect_err("must be refused");
        assert!(!out.join("sweep.csv").exists());
        format!("{e:#}")
    };
    let e = refused(&vary(&["simulation.duration=1e-5", "grid.size=1,2"]), false);
    assert!(
        e.contains("grid.size") && e.contains("unknown field"),
        "{e}"
    );
    let e = refused(&vary(&["simulation.duration=1e-5,abc"]), false);
    assert!(
        e.contains("simulation.duration") && e.contains("invalid type"),
        "{e}"
    );
    let e = refused(
        &vary(&["simulation.cfl=0.1,0.2", "simulation.cfl=0.3"]),
        false,
    );
    assert!(e.contains("given twice"), "{e}");
    let many: Vec<String> = (0..1001)
        .map(|k| format!("{}", 1e-6 * (k + 1) as f64))
        .collect();
    let big = vary(&[&format!("simulation.duration={}", many.join(","))]);
    let e = refused(&big, false);
    assert!(e.contains("1001 runs") && e.contains("--yes"), "{e}");
    // Five keys of 100 values are 1e10 runs: counted, not built (that took over 2 GB and
    // aborted), and refused even with --yes.
    let hundred: Vec<String> = (0..100)
        .map(|k| format!("{}", 0.1 + 1e-3 * k as f64))
        .collect();
    let keys = ["cfl", "damping", "duration", "thickness", "mass_tol"];
    let huge: Vec<String> = (keys.iter())
        .map(|k| format!("simulation.{k}={}", hundred.join(",")))
        .collect();
    let huge = vary(&huge.iter().map(String::as_str).collect::<Vec<_>>());
    let e = refused(&huge, true);
    assert!(e.contains("1.000e10 runs") && e.contains("10000"), "{e}");
    for bad in ["grid.cell", "grid.cell=", "grid.cell=[1e-3, 1e-3", "a=1,,2"] {
        assert!(Vary::parse(bad).is_err(), "{bad}");
    }
    std::fs::remove_dir_all(dir).ok();
}

/// With `[grid] anchor` the lattice follows the cell size: a crack line at y = 12 mm stays
/// half a cell from the node rows and the clamped edge x = 0 stays on a node column, at
/// 1 mm (where the anchor agrees with `min`, which is kept exactly), 0.7 mm and 0.3 mm
/// cells; the grid still covers [min, max].
#[test]
fn an_anchored_grid_keeps_the_scene_in_place_when_cells_change() {
    let text = |cell: f64| {
        format!(
            "[simulation]\ndimension = 2\nduration = 1e-6\n[grid]\nmin = [-0.003, -0.0035]\n\
             max = [0.106, 0.0275]\ncell = [{cell:e}, {cell:e}]\n\
             anchor = {{ point = [0.0, 0.012], offset = [0.0, 0.5] }}\n\
             [[material]]\nname = \"m\"\nE = 2.3e9\nnu = 0.33\nrho = 1500.0\n\
             [[body]]\nmaterial = \"m\"\nbox = {{ min = [0.0, 0.0], max = [0.1, 0.024] }}\n"
        )
    };
    for cell in [0.001, 0.0007, 0.0003] {
        let w =
            fissure::io::scenario::build::<fissure::base::dim::D2>(&common::source(&text(cell)))
                .unwrap_or_else(|e| panic!("{e}"))
                .world;
        let g = &w.grid.geom;
        if cell == 0.001 {
            assert_eq!((g.origin.x, g.origin.y), (-0.003, -0.0035));
        }
        let rows = (0.012 - g.origin.y) / cell;
        assert!((rows - rows.floor() - 0.5).abs() < 1e-9, "{cell}: {rows}");
        let columns = -g.origin.x / cell;
        assert!(
            (columns - columns.round()).abs() < 1e-9,
            "{cell}: {columns}"
        );
        assert!(g.origin.x <= -0.003 && g.origin.y <= -0.0035);
        let top = [
            g.origin.x + g.cells[0] as f64 * cell,
            g.origin.y + g.cells[1] as f64 * cell,
        ];
        assert!(
            top[0] >= 0.106 - 1e-12 && top[1] >= 0.0275 - 1e-12,
            "{top:?}"
        );
        assert!(top[0] < 0.106 + cell && top[1] < 0.0275 + cell, "{top:?}");
    }
}

/// Two expects of one quantity against two references get two columns each, told apart
/// by their references.
#[test]
fn repeated_expects_get_their_own_columns() {
    let (dir, file) = setup("repeated");
    let text = std::fs::read_to_string(&file).unwrap()
        + "[[expect]]\nquantity = \"energy_drift\"\nreference = 0.001\nsource = \"s\"\ntolerance = 2.0\n";
    std::fs::write(&file, text).unwrap();
    let out = dir.join("out");
    go(&file, &vary(&["simulation.shape=linear"]), &out);
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let head = csv.lines().next().unwrap();
    assert!(
        head.contains("energy_drift (reference 0e0) value")
            && head.contains("energy_drift (reference 1e-3) value"),
        "{head}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// A run refused at set-up (3 mm cells do not divide the 20 mm grid) is written as an
/// error row, and tried again when the sweep resumes: with the grid anchored (so any cell
/// size fits) it completes, and sweep.csv keeps one row per run.
#[test]
fn refused_runs_are_tried_again_on_resume() {
    let (dir, file) = setup("retry");
    let out = dir.join("out");
    let v = vary(&["grid.cell=[2e-3, 2e-3],[3e-3, 3e-3]"]);
    assert_eq!(go(&file, &v, &out), vec![(1, true), (2, false)]);
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert!(csv.lines().nth(2).unwrap().contains(",error,"), "{csv}");
    let text = std::fs::read_to_string(&file).unwrap().replacen(
        "cell = [0.002, 0.002]\n",
        "cell = [0.002, 0.002]\nanchor = { point = [0.0, 0.0] }\n",
        1,
    );
    std::fs::write(&file, text).unwrap();
    assert_eq!(go(&file, &v, &out), vec![(1, false), (2, true)]);
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3, "{csv}");
    assert!(lines[2].contains(",completed,"), "{csv}");
    std::fs::remove_dir_all(dir).ok();
}
