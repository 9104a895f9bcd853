//! Plain-MPM bar cases against closed forms (scenarios/reference/README.md, "Plain MPM"), in 2D and 3D.

mod common;
use common::{Bar, history};
use fissure::record::history::{arrival, energy_balance, frequency};

/// Probe averaging `quantity` `component` over the slice of particles in [x0, x1].
fn probe(bar: &Bar, name: &str, x0: f64, x1: f64, quantity: &str) -> String {
    format!(
        "\n[[probe]]\nname = \"{name}\"\nregion = {}\nquantity = \"{quantity}\"\ncomponent = \"x\"\n",
        bar.region(x0, x1)
    )
}

/// Speed of a step front between probes at 0.25 L and 0.75 L (half-amplitude arrivals).
fn front_speed(mut bar: Bar, extra_bc: &str) -> f64 {
    let (l, h) = (bar.len, bar.h);
    bar.extra = format!(
        "{}{}{}\n[[load]]\nregion = {}\nforce = {}\ntime = {{ kind = \"step\" }}\n",
        extra_bc,
        probe(&bar, "a", 0.25 * l, 0.25 * l + h, "velocity"),
        probe(&bar, "b", 0.75 * l, 0.75 * l + h, "velocity"),
        bar.region(0.0, h),
        common::v(bar.dim, 1e4, 0.0),
    );
    let hist = history(&bar.toml());
    let ta = arrival(&hist.time, &hist.probes[0]).expect("front reaches a");
    let tb = arrival(&hist.time, &hist.probes[1]).expect("front reaches b");
    0.5 * l / (tb - ta)
}

fn bar_speed_case(dim: usize) {
    // nu = 0: the bar speed is exactly c0 = sqrt(E/rho) = 5000 m/s at every wavelength.
    let bar = Bar {
        dim,
        duration: 0.95 * 0.1 / 5000.0 * 1.2,
        ..Bar::default()
    };
    let c = front_speed(bar, "");
    let c0 = (200e9f64 / 8000.0).sqrt();
    assert!(
        (c - c0).abs() / c0 < 0.02,
        "{dim}D bar speed {c} vs c0 {c0}"
    );
}

#[test]
fn bar_wave_speed_2d_matches_c0() {
    bar_speed_case(2);
}

#[test]
fn bar_wave_speed_3d_matches_c0() {
    bar_speed_case(3);
}

/// Plane strain with every node's lateral velocity fixed is uniaxial strain: the front
/// travels at the dilatational speed c_d = sqrt((lambda + 2 mu)/rho).
#[test]
fn uniaxial_strain_front_travels_at_dilatational_speed() {
    let bar = Bar {
        nu: 0.3,
        plane: "strain",
        duration: 0.95 * 0.1 / 5000.0,
        ..Bar::default()
    };
    let m = 2.0 * bar.h;
    let lateral = format!(
        "\n[[boundary]]\nregion = {{ min = [{:e}, {:e}], max = [{:e}, {:e}] }}\nfix = [\"y\"]\n",
        -m,
        -m,
        bar.len + m,
        bar.w + m
    );
    let c = front_speed(bar, &lateral);
    let (e, nu, rho) = (200e9f64, 0.3, 8000.0);
    let cd = (e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)) / rho).sqrt();
    assert!(
        (c - cd).abs() / cd < 0.02,
        "uniaxial-strain speed {c} vs c_d {cd}"
    );
}

/// Fixed-free bar released with a uniform velocity: the end oscillates at f = c0/(4L).
fn first_mode_case(dim: usize) -> (f64, f64) {
    let mut bar = Bar {
        dim,
        velocity: 1.0,
        duration: 5.0 * 4.0 * 0.1 / 5000.0,
        ..Bar::default()
    };
    bar.extra = format!(
        "\n[[boundary]]\nregion = {}\nfix = [\"x\"]\n{}",
        bar.left_nodes(),
        probe(&bar, "tip", bar.len - bar.h, bar.len, "displacement")
    );
    let hist = history(&bar.toml());
    let f = frequency(&hist.time, &hist.probes[0]).expect("oscillates");
    let total = |r: &fissure::record::history::Row| r.energies.kinetic + r.energies.strain;
    let e0 = total(&hist.rows[0]);
    let drift = (total(hist.rows.last().unwrap()) - e0) / e0;
    (f, drift)
}

#[test]
fn fixed_free_bar_first_mode_2d() {
    let (f, drift) = first_mode_case(2);
    let f0 = 5000.0 / (4.0 * 0.1);
    assert!(
        (f - f0).abs() / f0 < 0.02,
        "2D first mode {f} Hz vs c0/(4L) = {f0} Hz"
    );
    // Undamped energy drift over five periods. With the momentum remap before the final
    // stress update the scheme is nearly conservative (measured -0.05 % here; without the
    // remap it lost 3.7 %); bound it at 0.5 %. A growing energy would mean instability.
    assert!(drift.abs() < 5e-3, "energy drift over 5 periods {drift}");
    assert!(drift <= 1e-9, "energy grew: {drift}");
}

#[test]
fn fixed_free_bar_first_mode_3d() {
    let (f, _) = first_mode_case(3);
    let f0 = 5000.0 / (4.0 * 0.1);
    assert!(
        (f - f0).abs() / f0 < 0.02,
        "3D first mode {f} Hz vs c0/(4L) = {f0} Hz"
    );
}

/// A ramped end force on a clamped bar, damped to rest: elongation P L / (E A), and the
/// opening across the middle 0.4 L (a clip gauge: the halves' centroids 0.2 L apart) of
/// P / (E A) x 0.2 L. Returns both relative errors.
fn damped_elongation_case(dim: usize) -> (f64, f64) {
    let omega1 = 2.0 * std::f64::consts::PI * 5000.0 / (4.0 * 0.1);
    let mut bar = Bar {
        dim,
        nu: 0.3,
        damping: 2.0 * omega1,
        duration: 30.0 / omega1,
        ..Bar::default()
    };
    let p = 1e4;
    bar.extra = format!(
        "\n[[boundary]]\nregion = {}\nfix = [\"x\"]\n{}{}\n[[load]]\nregion = {}\nforce = {}\ntime = {{ kind = \"ramp\", rise = {:e} }}\n",
        bar.left_nodes(),
        probe(&bar, "tip", bar.len - bar.h, bar.len, "displacement"),
        probe(&bar, "gauge", 0.3 * bar.len, 0.7 * bar.len, "opening"),
        bar.region(bar.len - bar.h, bar.len),
        common::v(dim, p, 0.0),
        2.0 / omega1
    );
    let out = common::run_text(&bar.toml());
    let strain = p / (200e9 * bar.area());
    // summary.json reports each probe's last sample.
    let last = |k: usize| {
        let r = &out.summary.probes[k];
        assert_eq!(r.last, out.history.probes[k].last().copied(), "{}", r.name);
        r.last.unwrap()
    };
    let error = |k: usize, want: f64| (last(k) - want) / want;
    (error(0, strain * bar.len), error(1, strain * 0.2 * bar.len))
}

#[test]
fn damped_bar_elongation_2d() {
    let (tip, gauge) = damped_elongation_case(2);
    assert!(tip.abs() < 0.02, "2D elongation error {tip}");
    assert!(gauge.abs() < 0.02, "2D clip-gauge opening error {gauge}");
}

#[test]
fn damped_bar_elongation_3d() {
    let (tip, gauge) = damped_elongation_case(3);
    assert!(tip.abs() < 0.02, "3D elongation error {tip}");
    assert!(gauge.abs() < 0.02, "3D clip-gauge opening error {gauge}");
}

/// Non-cubic cells (1 x 2.5 mm): the front still travels at c0 along the bar.
#[test]
fn bar_wave_speed_with_non_cubic_cells() {
    let bar = Bar {
        h: 0.001,
        duration: 0.95 * 0.1 / 5000.0 * 1.2,
        ..Bar::default()
    };
    // Same bar, grid rows 2.5 mm tall: replace the [grid] table.
    let full = bar.toml();
    let start = full.find("[grid]").unwrap();
    let end = full.find("[[material]]").unwrap();
    let grid = "[grid]\nmin = [-2e-3, -5e-3]\nmax = [0.102, 0.015]\ncell = [1e-3, 2.5e-3]\n\n";
    let text = format!("{}{grid}{}", &full[..start], &full[end..]);
    assert!(text.contains("cell = [1e-3, 2.5e-3]"), "{text}");
    let (l, h) = (bar.len, bar.h);
    let extra = format!(
        "{}{}\n[[load]]\nregion = {}\nforce = [1e4, 0.0]\ntime = {{ kind = \"step\" }}\n",
        probe(&bar, "a", 0.25 * l, 0.25 * l + h, "velocity"),
        probe(&bar, "b", 0.75 * l, 0.75 * l + h, "velocity"),
        bar.region(0.0, h),
    );
    let hist = history(&format!("{text}{extra}"));
    let ta = arrival(&hist.time, &hist.probes[0]).expect("front reaches a");
    let tb = arrival(&hist.time, &hist.probes[1]).expect("front reaches b");
    let c = 0.5 * l / (tb - ta);
    assert!(
        (c - 5000.0).abs() / 5000.0 < 0.02,
        "speed {c} with 1 x 2.5 mm cells"
    );
}

/// A grip moving at a prescribed velocity drags the end of a clamped bar with it: after
/// the ramp the end particles follow the grip's displacement v (t - t_ramp/2); the grip's
/// reaction does the work that the bar stores and carries (energy balance within 1 %).
#[test]
fn prescribed_velocity_moves_the_grip() {
    let mut bar = Bar {
        duration: 2e-5,
        ..Bar::default()
    };
    let m = 2.0 * bar.h;
    bar.extra = format!(
        "\n[[boundary]]\nregion = {}\nfix = [\"x\"]\n\n[[boundary]]\nregion = {{ min = [{:e}, {:e}], max = [{:e}, {:e}] }}\nfix = [\"x\"]\nvelocity = [0.5, 0.0]\ntime = {{ kind = \"ramp\", rise = 4e-6 }}\n{}",
        bar.left_nodes(),
        bar.len,
        -m,
        bar.len + m,
        bar.w + m,
        probe(&bar, "end", bar.len - 0.25 * bar.h, bar.len, "displacement"),
    );
    let hist = history(&bar.toml());
    let t = *hist.time.last().unwrap();
    let want = 0.5 * (t - 2e-6);
    let got = *hist.probes[0].last().unwrap();
    assert!(
        (got - want).abs() / want < 0.02,
        "grip displacement {got} vs {want}"
    );
    let last = &hist.rows.last().unwrap().energies;
    assert!(
        last.external_work > 0.5 * (last.kinetic + last.strain),
        "{last:?}"
    );
    let balance = energy_balance(&hist).unwrap();
    assert!(balance < 0.01, "energy balance off by {balance}");
}
