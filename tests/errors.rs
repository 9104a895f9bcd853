//! Bad input gets a clear error naming file, line and key, never a panic; the launcher
//! exits with code 2.

use fissure::base::dim::D2;
use fissure::base::error::ScenarioError;
use fissure::io::scenario::{Source, build};

const GOOD: &str = r#"name = "good"
[simulation]
dimension = 2
duration = 1e-4
cfl = 0.5
[grid]
min = [0.0, 0.0]
max = [0.02, 0.02]
cell = [0.002, 0.002]
[[material]]
name = "steel"
E = 200e9
nu = 0.3
rho = 7800.0
[[body]]
material = "steel"
box = { min = [0.004, 0.004], max = [0.016, 0.016] }
"#;

/// The build error of a scenario text that parses.
fn refused(text: &str) -> ScenarioError {
    match build::<D2>(&Source::parse("bad.toml", text, &[]).unwrap()) {
        Ok(_) => panic!("scenario must be refused"),
        Err(e) => e,
    }
}

/// Loads `GOOD` with `overrides` and returns the error it must produce.
fn error_with(overrides: &[&str]) -> ScenarioError {
    let ov: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    match Source::parse("bad.toml", GOOD, &ov) {
        Err(e) => e,
        Ok(src) => match build::<D2>(&src) {
            Ok(_) => panic!("scenario must be refused"),
            Err(e) => e,
        },
    }
}

fn assert_error(e: &ScenarioError, key: &str, line: Option<usize>, words: &str) {
    let msg = e.to_string();
    assert_eq!(e.key.as_deref(), Some(key), "{msg}");
    if line.is_some() {
        assert_eq!(e.line, line, "{msg}");
    }
    assert!(msg.contains(words), "`{msg}` should mention `{words}`");
    assert!(msg.starts_with("bad.toml"), "{msg}");
}

#[test]
fn good_scenario_builds() {
    let src = Source::parse("good.toml", GOOD, &[]).unwrap();
    // A 12 mm square at 2 mm cells and 2 particles per cell per axis: 12 x 12 particles.
    assert_eq!(build::<D2>(&src).unwrap().world.particles.len(), 144);
}

#[test]
fn unknown_key_names_line_and_key() {
    let text = GOOD.replace("cfl = 0.5", "cfl = 0.5\ncourant = 0.3");
    let e = Source::parse("bad.toml", &text, &[]).unwrap_err();
    assert_eq!(e.line, Some(6), "{e}");
    assert!(e.to_string().contains("courant"), "{e}");
}

#[test]
fn wrong_type_names_line_and_key() {
    let text = GOOD.replace("nu = 0.3", "nu = \"a third\"");
    let e = Source::parse("bad.toml", &text, &[]).unwrap_err();
    assert_eq!(e.line, Some(13), "{e}");
    assert_eq!(e.key.as_deref(), Some("material[0].nu"), "{e}");
}

#[test]
fn missing_material() {
    let e = refused(&GOOD.replace("material = \"steel\"", "material = \"titanium\""));
    assert_error(
        &e,
        "body[0].material",
        Some(16),
        "no [[material]] named `titanium`",
    );
}

#[test]
fn body_outside_the_grid() {
    let e = error_with(&["body[0].box.max=[0.03, 0.016]"]);
    assert_error(&e, "body[0]", None, "beyond the grid");
    // A 2 m box in a 20 mm grid was cut to the grid in silence: both boxes are named.
    let e = error_with(&["body[0].box.min=[-1.0, -1.0]", "body[0].box.max=[1.0, 1.0]"]);
    assert_error(
        &e,
        "body[0]",
        None,
        "the body spans (-1.0000e0, -1.0000e0) to",
    );
    assert!(
        e.to_string()
            .contains("the grid (0.0000e0, 0.0000e0) to (2.0000e-2, 2.0000e-2) m"),
        "{e}"
    );
    // A body the grid would cut is accepted when its clip or a hole keeps it inside.
    let builds = |set: &[&str]| {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        build::<D2>(&Source::parse("inside.toml", GOOD, &set).expect("parses")).is_ok()
    };
    assert!(builds(&[
        "body[0].box.max=[0.03, 0.016]",
        "body[0].clip={ min = [0.0, 0.0], max = [0.016, 0.016] }"
    ]));
    assert!(builds(&[
        "body[0].box.max=[0.021, 0.016]",
        "body[0].holes=[{ center = [0.021, 0.01], radius = 0.008 }]"
    ]));
}

#[test]
fn non_positive_modulus_and_density() {
    assert_error(
        &refused(&GOOD.replace("E = 200e9", "E = -1.0")),
        "material[0].E",
        Some(12),
        "positive",
    );
    assert_error(
        &refused(&GOOD.replace("rho = 7800.0", "rho = 0.0")),
        "material[0].rho",
        Some(14),
        "positive",
    );
}

#[test]
fn poisson_ratio_at_or_above_half() {
    let e = refused(&GOOD.replace("nu = 0.3", "nu = 0.5"));
    assert_error(&e, "material[0].nu", Some(13), "nu < 0.5");
}

#[test]
fn cfl_at_or_above_one() {
    let e = refused(&GOOD.replace("cfl = 0.5", "cfl = 1.0"));
    assert_error(&e, "simulation.cfl", Some(5), "0 < cfl < 1");
}

#[test]
fn time_step_above_the_stability_limit() {
    // limit = 2 mm / c_d, c_d = sqrt((lambda + 2 mu)/rho) = 5875 m/s: 3.4e-7 s.
    let text = GOOD.replace("cfl = 0.5", "dt = 1e-6");
    let e = refused(&text);
    assert_error(&e, "simulation.dt", Some(5), "above the stability limit");
}

/// A scene larger than the machine's free memory (a 3D body of 16^3 particles per cell
/// over 100^3 cells, about 2 TB) is refused before anything is allocated, with the
/// estimate; no machine this runs on has that much free.
#[test]
fn a_scene_too_large_for_memory_is_refused_at_once() {
    let text = text_3d("")
        .replace(
            "cell = [0.002, 0.002, 0.002]",
            "cell = [0.0002, 0.0002, 0.0002]",
        )
        .replace(
            "box = { min = [0.004, 0.004, 0.004]",
            "ppc = 16\nbox = { min = [0.0, 0.0, 0.0]",
        )
        .replace(
            "max = [0.016, 0.016, 0.016] }",
            "max = [0.02, 0.02, 0.02] }",
        );
    let src = Source::parse("bad.toml", &text, &[]).unwrap();
    match fissure::io::scenario::build::<fissure::base::dim::D3>(&src) {
        Ok(_) => panic!("a 2 TB scene must be refused"),
        Err(e) => assert_error(&e, "grid.cell", None, "this machine has"),
    }
}

/// No body, a body with no particle, also once clipped, and a tube or ring whose hole is
/// not inside it.
#[test]
fn empty_body() {
    // No [[body]] at all: the file's last line, where one would go, is named.
    let text = GOOD.split("[[body]]").next().unwrap();
    let e = match Source::parse("bad.toml", text, &[]) {
        Err(e) => e,
        Ok(src) => match build::<D2>(&src) {
            Ok(_) => panic!("a scenario without a body must be refused"),
            Err(e) => e,
        },
    };
    assert_error(
        &e,
        "body",
        Some(text.lines().count()),
        "has no [[body]]: add one",
    );
    let e = error_with(&["body[0].box.max=[0.0045, 0.0045]"]);
    assert_error(&e, "body[0]", None, "no particle");
    let e = error_with(&["body[0].clip={ point = [0.0, 0.017], normal = [0.0, 1.0] }"]);
    assert_error(&e, "body[0]", None, "clipped or cut away");
    let e = error_3d(
        "[[body]]\nmaterial = \"steel\"\ncylinder = { center = [0.01, 0.01, 0.005], \
         axis = \"z\", radius = 0.003, inner_radius = 0.003, length = 0.01 }\n",
    );
    assert_error(&e, "body[1].cylinder.inner_radius", None, "bore's radius");
    let e = error_with_text(
        "[[body]]\nmaterial = \"steel\"\ndisc = { center = [0.01, 0.01], radius = 0.003, \
         inner_radius = -0.001 }\n",
    );
    assert_error(&e, "body[1].disc.inner_radius", None, "hole's radius");
    let e = error_with(&["body[0].holes=[{ center = [0.01, 0.01], radius = 0.0 }]"]);
    assert_error(&e, "body[0].holes[0].radius", None, "positive");
    let e = error_with(&[
        "body[0].holes=[{ center = [0.01, 0.01], radius = 0.002, inner_radius = 0.001 }]",
    ]);
    assert_error(&e, "body[0].holes[0].inner_radius", None, "does not apply");
    let e = error_with(&["body[0].holes=[{ center = [0.01, 0.01], radius = 0.02 }]"]);
    assert_error(&e, "body[0]", None, "or cut away");
    // A body inside the one listed before it has no points of its own.
    let e = error_with_text(
        "[[body]]\nmaterial = \"steel\"\nbox = { min = [0.006, 0.006], max = [0.01, 0.01] }\n",
    );
    assert_error(
        &e,
        "body[1]",
        None,
        "covered by the bodies listed before it",
    );
    let e = error_with_text(
        "[[body]]\nmaterial = \"steel\"\npolygon = { points = [[0.002, 0.002], [0.018, 0.018], \
         [0.018, 0.002], [0.002, 0.018]] }\n",
    );
    assert_error(
        &e,
        "body[1].polygon.points",
        None,
        "crosses itself: edges 0 and 2",
    );
}

#[test]
fn bad_grid_anchors_name_the_key() {
    let e = error_with(&["grid.anchor={ point = [0.0, 0.0], offset = [0.0, 1.0] }"]);
    assert_error(&e, "grid.anchor.offset", None, "[0, 1)");
    let e = error_with(&["grid.anchor={ point = [0.0] }"]);
    assert_error(&e, "grid.anchor.point", None, "2 components");
}

#[test]
fn malformed_override_is_refused() {
    let e = Source::parse("bad.toml", GOOD, &["simulation.cfl".into()]).unwrap_err();
    assert!(
        e.to_string().contains("KEY=VALUE") || e.to_string().contains("path.to.key=value"),
        "{e}"
    );
}

#[test]
fn launcher_exits_with_code_2_on_bad_input() {
    let dir = std::env::temp_dir().join(format!("fissure-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bad.toml");
    std::fs::write(&file, GOOD.replace("nu = 0.3", "nu = 0.7")).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
        .args(["check", file.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("bad.toml:13") && stderr.contains("material[0].nu"),
        "{stderr}"
    );
    let missing = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
        .args(["run", dir.join("nope.toml").to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(2));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_checkpoint_settings_name_the_key() {
    let e = error_with(&["checkpoint.keep=0"]);
    assert_error(&e, "checkpoint.keep", None, "at least 1");
    let e = error_with(&["checkpoint.every_time=-1e-6"]);
    assert_error(&e, "checkpoint.every_time", None, "positive");
    let e = error_with(&["checkpoint.every_steps=0"]);
    assert_error(&e, "checkpoint.every_steps", None, "at least 1");
    let e = Source::parse("bad.toml", &format!("{GOOD}[checkpoint]\nevery = 3\n"), &[])
        .expect_err("unknown key");
    assert!(e.to_string().contains("every") && e.line == Some(19), "{e}");
}

/// Builds `GOOD` plus `extra` and returns the error it must produce.
fn error_with_text(extra: &str) -> ScenarioError {
    let text = format!("{GOOD}{extra}");
    match Source::parse("bad.toml", &text, &[]) {
        Err(e) => e,
        Ok(src) => match build::<D2>(&src) {
            Ok(_) => panic!("scenario must be refused"),
            Err(e) => e,
        },
    }
}

#[test]
fn bad_cracks_name_the_key() {
    let e = error_with_text("[[crack]]\npoints = [[0.0001, 0.0001], [0.0001, 0.002]]\n");
    assert_error(&e, "crack[0].points", Some(19), "front vertex 1");
    let e = error_with_text("[[crack]]\npoints = [[0.0001, 0.0001], [0.0001, 0.002]]\ntips = []\n");
    assert_error(
        &e,
        "crack[0].points",
        Some(19),
        "the crack is outside every body",
    );
    let e = error_with_text("[[crack]]\npoints = [[0.01, 0.01]]\n");
    assert_error(&e, "crack[0].points", Some(19), "at least two points");
    let e = error_with_text(
        "[[crack]]\npoints = [[0.006, 0.006], [0.014, 0.014], [0.014, 0.006], [0.006, 0.014]]\n",
    );
    assert_error(&e, "crack[0].points", Some(19), "crosses itself");
    // Folded back 1e-10 m above itself: nothing crosses, but the faces would overlap.
    let e = error_with_text(
        "[[crack]]\npoints = [[0.006, 0.01], [0.014, 0.01], [0.006, 0.0100000001]]\n",
    );
    assert_error(
        &e,
        "crack[0].points",
        Some(19),
        "folds back on itself at point 1",
    );
    let e = error_with_text(
        "[[crack]]\npoints = [[0.006, 0.01], [0.012, 0.01]]\ntips = [\"middle\"]\n",
    );
    assert_error(&e, "crack[0].tips", Some(20), "unknown tip");
    let e = error_with_text("[[crack]]\npoints = [[0.006, 0.01], [0.03, 0.01]]\n");
    assert_error(&e, "crack[0].points", Some(19), "outside the grid");
    let e = error_with_text("[[crack]]\nline = { start = [0.006, 0.01], end = [0.006, 0.01] }\n");
    assert_error(&e, "crack[0].line.end", None, "coincide");
    let e = error_with_text("[[crack]]\ntips = [\"end\"]\n");
    assert_error(&e, "crack[0]", None, "exactly one of");
    // Names that would break the CSV files they head or fill.
    let e = error_with_text(
        "[[crack]]\nname = \"a\\\"b\"\nline = { start = [0.006, 0.01], end = [0.012, 0.01] }\n",
    );
    assert_error(&e, "crack[0].name", None, "without commas, double quotes");
    let e = error_with_text(
        "[[probe]]\nname = \"x,y\"\nregion = { min = [0.004, 0.004], max = [0.006, 0.006] }\n\
         quantity = \"velocity\"\ncomponent = \"x\"\n",
    );
    assert_error(&e, "probe[0].name", None, "`x,y` names a column");
}

#[test]
fn bad_fracture_requests_name_the_key() {
    let crack = "[[crack]]\npoints = [[0.003, 0.01], [0.01, 0.01]]\n";
    let e = error_with_text("[fracture]\ncontour = 2\n");
    assert_error(&e, "fracture", None, "at least one [[crack]]");
    let e = error_with_text(&format!("{crack}tips = []\n[fracture]\n"));
    assert_error(&e, "fracture", None, "no crack has one");
    let e = error_with_text(&format!("{crack}[fracture]\ncontour = 6\n"));
    assert_error(&e, "fracture.contour", None, "leaves the grid");
    let e = error_with_text(&format!("{crack}[fracture]\nopening = 1.0\n"));
    assert_error(&e, "fracture.opening", None, "at least 2");
    let e = error_with_text(&format!("{crack}[fracture]\ncompare = [8]\n"));
    assert_error(&e, "fracture.compare", None, "leaves the grid");
    let e = error_with_text(&format!("{crack}[fracture]\ncompare_from = -1.0\n"));
    assert_error(&e, "fracture.compare_from", None, ">= 0");
    let e = error_with_text(&format!("{crack}[fracture]\nk0 = 0.0\n"));
    assert_error(&e, "fracture.k0", None, "positive");
    let expect = |body: &str| {
        format!(
            "{crack}[fracture]\n[[expect]]\ncrack = \"crack0\"\nreference = 0.0\nsource = \"s\"\ntolerance = 0.1\n{body}"
        )
    };
    let e = error_with_text(&expect("quantity = \"J_path\"\n"));
    assert_error(&e, "expect[0].quantity", None, "[fracture] compare");
    let e = error_with_text(&expect("quantity = \"KI\"\nat = 1.0\n"));
    assert_error(&e, "expect[0].at", None, "must lie in the run");
    let e = error_with_text(&expect("quantity = \"max\"\nat = 1e-5\n"));
    assert_error(&e, "expect[0].at", None, "applies to final");
    let e = error_with_text(&expect("quantity = \"K_drift\"\n"));
    assert_error(&e, "expect[0].from", None, "give its start");
    let e = error_with_text(&expect("quantity = \"K_drift\"\nfrom = 0.0\nat = 1e-6\n"));
    assert_error(&e, "expect[0].at", None, "runs over a window");
    let e = error_with_text(&expect("quantity = \"G_interaction\"\n"));
    assert_error(&e, "expect[0].from", None, "give its start");
    let e = error_with_text(&expect(
        "quantity = \"G_interaction\"\nfrom = 0.0\nat = 1e-6\n",
    ));
    assert_error(&e, "expect[0].at", None, "runs over a window");
    let e = error_with_text(&expect(
        "quantity = \"G_interaction\"\nfrom = 0.0\nmaterial = \"glass\"\n",
    ));
    assert_error(
        &e,
        "expect[0].material",
        None,
        "no [[material]] named `glass`",
    );
    let e = error_with_text(&expect("quantity = \"KI\"\nmaterial = \"steel\"\n"));
    assert_error(&e, "expect[0].material", None, "applies to G_interaction");
    let e = error_with_text(&format!(
        "[[material]]\nname = \"glass\"\nE = 70e9\nnu = 0.2\nrho = 2500.0\n{}",
        expect("quantity = \"G_interaction\"\nfrom = 0.0\n")
    ));
    assert_error(&e, "expect[0].material", None, "several materials");
    let e = error_with_text(&expect("quantity = \"KI\"\nfrom = 1e-5\n"));
    assert_error(&e, "expect[0].from", None, "applies to K_drift");
    let e = error_with_text(&expect("quantity = \"kinetic_fraction\"\nfrom = 1.0\n"));
    assert_error(&e, "expect[0].from", None, "give its start");
    let e = error_with_text(&format!("{crack}[fracture]\nk_from = \"fit\"\n"));
    assert_error(&e, "fracture.k_from", None, "unknown method `fit`");
    let e = error_with_text(&format!("{crack}[fracture]\ndomain = 1.5\n"));
    assert_error(&e, "fracture.domain", None, "at least 2");
    let e = error_with_text(&format!(
        "{crack}[fracture]\n[[expect]]\nquantity = \"KI\"\ncrack = \"crack0\"\ntip = \"start\"\nreference = 1.0\nsource = \"s\"\ntolerance = 0.1\n"
    ));
    assert_error(&e, "expect[0].tip", None, "not a tip");
}

#[test]
fn bad_contact_settings_name_the_key() {
    let crack = "[[crack]]\npoints = [[0.006, 0.01], [0.012, 0.01]]\n";
    let e = error_with_text(&format!("{crack}contact = {{ law = \"glue\" }}\n"));
    assert_error(&e, "crack[0].contact.law", None, "unknown contact law");
    let e = error_with_text(&format!("{crack}split = \"visible\"\n"));
    assert_error(&e, "crack[0].split", None, "unknown split rule `visible`");
    let e = error_with_text(&format!("{crack}contact = {{ law = \"friction\" }}\n"));
    assert_error(&e, "crack[0].contact.friction", None, "coefficient");
    let e = error_with_text(&format!(
        "{crack}contact = {{ law = \"friction\", friction = -0.1 }}\n"
    ));
    assert_error(&e, "crack[0].contact.friction", None, ">= 0");
    let e = error_with_text(&format!(
        "{crack}contact = {{ law = \"stick\", friction = 0.1 }}\n"
    ));
    assert_error(
        &e,
        "crack[0].contact.friction",
        None,
        "only the `friction` law",
    );
}

#[test]
fn bad_loads_name_the_key() {
    let region = "region = { min = [0.015, 0.004], max = [0.016, 0.016] }\n";
    let field = "williams = { KI = 1e6, KII = 0.0, tip = [0.01, 0.01] }\n";
    let e = error_with_text(&format!("[[load]]\n{region}"));
    assert_error(&e, "load[0]", None, "give `force`");
    let e = error_with_text(&format!("[[load]]\n{region}force = [1.0, 0.0]\n{field}"));
    assert_error(&e, "load[0].force", None, "not both");
    let e = error_with_text(&format!("[[load]]\n{region}{field}"));
    assert_error(&e, "load[0].normal", None, "outward normal");
    let e = error_with_text(&format!("[[load]]\n{region}{field}normal = [0.0, 0.0]\n"));
    assert_error(&e, "load[0].normal", None, "must not be zero");
    let e = error_with_text(&format!(
        "[[load]]\n{region}normal = [1.0, 0.0]\nwilliams = {{ KI = 1e6, KII = 0.0, tip = [0.016, 0.0095] }}\n"
    ));
    assert_error(&e, "load[0].region", None, "singular");
    let e = error_with_text(&format!(
        "[[load]]\n{region}normal = [1.0, 0.0]\ncentre_crack = {{ stress = [0.0, nan, 0.0], center = [0.01, 0.01], half_length = 0.002 }}\n"
    ));
    assert_error(&e, "load[0].centre_crack.stress", None, "finite");
    let e = error_with_text(&format!(
        "[[load]]\n{region}normal = [1.0, 0.0]\ncentre_crack = {{ stress = [0.0, 1e6, 0.0], center = [0.01, 0.01], half_length = inf }}\n"
    ));
    assert_error(&e, "load[0].centre_crack.half_length", None, "finite");
    let e = error_with_text(&format!(
        "[[load]]\n{region}normal = [1.0, 0.0]\nwilliams = {{ KI = inf, KII = 0.0, tip = [0.01, 0.01] }}\n"
    ));
    assert_error(&e, "load[0].williams", None, "finite");
    let e = error_with_text(&format!(
        "[[load]]\n{region}force = [1.0, 0.0]\nnormal = [1.0, 0.0]\n"
    ));
    assert_error(&e, "load[0].normal", None, "goes with a traction");
    let pressure = |p: &str| error_with_text(&format!("[[load]]\n{region}pressure = {p}\n"));
    let e = pressure("{ value = nan }");
    assert_error(&e, "load[0].pressure.value", None, "finite");
    let e = pressure("{ value = 1e6 }");
    assert_error(&e, "load[0].normal", None, "outward normal");
    let e = pressure("{ value = 1e6, center = [0.01, 0.01] }");
    assert_error(&e, "load[0].pressure.face", None, "\"inner\"");
    let e = pressure("{ value = 1e6, face = \"inner\" }\nnormal = [1.0, 0.0]");
    assert_error(&e, "load[0].pressure.face", None, "round face's `center`");
    let e =
        pressure("{ value = 1e6, center = [0.01, 0.01], face = \"outer\" }\nnormal = [1.0, 0.0]");
    assert_error(&e, "load[0].normal", None, "leave out `normal`");
    let e = pressure(&format!("{{ value = 1e6 }}\nnormal = [1.0, 0.0]\n{field}"));
    assert_error(&e, "load[0].pressure", None, "give one traction");
}

#[test]
fn bad_regions_name_the_key() {
    let load = |region: &str| {
        error_with_text(&format!(
            "[[load]]\nregion = {region}\nforce = [1.0, 0.0]\n"
        ))
    };
    let e = load("{ polygon = [[0.005, 0.005], [0.01, 0.005], [0.015, 0.005]] }");
    assert_error(&e, "load[0].region.polygon", None, "degenerate");
    let e = load("{ polygon = [[0.005, 0.005], [0.015, 0.015], [0.015, 0.005], [0.005, 0.015]] }");
    assert_error(&e, "load[0].region.polygon", None, "crosses itself");
    let e = load("{ point = [0.01, 0.01], normal = [0.0, 0.0] }");
    assert_error(&e, "load[0].region.normal", None, "non-zero length");
    let e = load("{ center = [0.01, 0.01], half = [0.001, 0.0], angle = 30.0 }");
    assert_error(&e, "load[0].region.half", None, "positive");
    let e = load("{ center = [0.01, 0.01], half = [0.001, 0.001] }");
    assert_error(&e, "load[0].region.angle", None, "finite `angle`");
    let e = load("{ min = [0.005, 0.005], polygon = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] }");
    assert_error(&e, "load[0].region", None, "exactly one shape");
    let e = load("{ center = [0.03, 0.03], half = [0.001, 0.001], angle = 45.0 }");
    assert_error(&e, "load[0].region", None, "no particle");
    let e = load("{ center = [0.01, 0.01], radius = -0.001 }");
    assert_error(&e, "load[0].region.radius", None, "positive");
    let e = load("{ center = [0.01, 0.01], radius = 0.001, half = [0.001, 0.001] }");
    assert_error(&e, "load[0].region", None, "not both");
    let e = load("{ min = [0.005, 0.005], max = [0.01, 0.01], radius = 0.001 }");
    assert_error(&e, "load[0].region.radius", None, "`center`");
}

/// `GOOD` in 3D (a 12 mm cube in a 20 mm grid) with `extra` appended, and its error.
/// The good scenario made 3D, with `extra` appended.
fn text_3d(extra: &str) -> String {
    GOOD.replace("dimension = 2", "dimension = 3")
        .replace("[0.0, 0.0]", "[0.0, 0.0, 0.0]")
        .replace("[0.02, 0.02]", "[0.02, 0.02, 0.02]")
        .replace("[0.002, 0.002]", "[0.002, 0.002, 0.002]")
        .replace("[0.004, 0.004]", "[0.004, 0.004, 0.004]")
        .replace("[0.016, 0.016]", "[0.016, 0.016, 0.016]")
        + extra
}

fn error_3d(extra: &str) -> ScenarioError {
    let text = text_3d(extra);
    match Source::parse("bad.toml", &text, &[]) {
        Err(e) => e,
        Ok(src) => match fissure::io::scenario::build::<fissure::base::dim::D3>(&src) {
            Ok(_) => panic!("scenario must be refused"),
            Err(e) => e,
        },
    }
}

#[test]
fn bad_crack_surfaces_name_the_problem() {
    let mesh = |v: &str, t: &str| {
        error_3d(&format!(
            "[[crack]]\nmesh = {{ vertices = [{v}], triangles = [{t}] }}\n"
        ))
    };
    let square = "[0.006, 0.006, 0.01], [0.014, 0.006, 0.01], [0.014, 0.014, 0.01], \
                  [0.006, 0.014, 0.01], [0.01, 0.01, 0.014]";
    let e = mesh(square, "[0, 1, 2], [0, 2, 3], [0, 2, 4]");
    assert_error(&e, "crack[0].mesh", Some(19), "not a manifold");
    let e = mesh(square, "[0, 1, 2], [0, 3, 2]");
    assert_error(&e, "crack[0].mesh", Some(19), "oriented oppositely");
    let e = mesh(square, "[0, 1, 1]");
    assert_error(&e, "crack[0].mesh", Some(19), "degenerate");
    // A front must walk the boundary (0-1-2-3 around the square): a repeated vertex and a
    // skipped one (1 then 3, across the diagonal) were accepted and measured as NaN.
    let fronted = |front: &str| {
        error_3d(&format!(
            "[[crack]]\nmesh = {{ vertices = [{square}], triangles = [[0, 1, 2], [0, 2, 3]], \
             front = [{front}] }}\n"
        ))
    };
    let e = fronted("0, 1, 1, 2");
    assert_error(
        &e,
        "crack[0].mesh",
        Some(19),
        "front vertex 1 is listed twice",
    );
    let e = fronted("1, 3, 0, 2");
    assert_error(
        &e,
        "crack[0].mesh",
        Some(19),
        "front vertices 1 and 3 follow each other",
    );
    // Folded flat along the edge 1-2: the second triangle lies back over the first.
    let folded = "[0.006, 0.006, 0.01], [0.014, 0.006, 0.01], [0.006, 0.014, 0.01], \
                  [0.009, 0.009, 0.0101]";
    let e = mesh(folded, "[0, 1, 2], [2, 1, 3]");
    assert_error(
        &e,
        "crack[0].mesh",
        Some(19),
        "fold over each other along edge 1-2",
    );
    let e = mesh(
        "[0.006, 0.006, 0.01], [0.01, 0.006, 0.01], [0.014, 0.006, 0.01]",
        "[0, 1, 2]",
    );
    assert_error(&e, "crack[0].mesh", Some(19), "no area");
    // Two triangles sharing no vertex: one through the other, then one lying over the other.
    let apart = "[0.006, 0.006, 0.01], [0.014, 0.006, 0.01], [0.006, 0.014, 0.01], \
                 [0.008, 0.008, 0.006], [0.008, 0.008, 0.014], [0.012, 0.012, 0.01]";
    let e = mesh(apart, "[0, 1, 2], [3, 4, 5]");
    assert_error(&e, "crack[0]", Some(18), "meets itself (triangles 0 and 1");
    let over = "[0.006, 0.006, 0.01], [0.014, 0.006, 0.01], [0.006, 0.014, 0.01], \
                [0.008, 0.008, 0.01], [0.013, 0.008, 0.01], [0.008, 0.013, 0.01]";
    let e = mesh(over, "[0, 1, 2], [3, 4, 5]");
    assert_error(&e, "crack[0]", Some(18), "meets itself (triangles 0 and 1");
    let e = mesh(square, "[0, 1, 7]");
    assert_error(
        &e,
        "crack[0].mesh.triangles",
        Some(19),
        "vertex 7 does not exist",
    );
    let e = error_3d(
        "[[crack]]\npenny = { center = [0.01, 0.01, 0.01], normal = [0.0, 0.0, 0.0], radius = 0.003 }\n",
    );
    assert_error(&e, "crack[0].penny.normal", Some(19), "must not be zero");
    let e = error_3d(
        "[[crack]]\nrectangle = { center = [0.01, 0.01, 0.01], axes = [[0.003, 0.0, 0.0], [0.006, 0.0, 0.0]] }\n",
    );
    assert_error(&e, "crack[0].rectangle.axes", Some(19), "not parallel");
    let e =
        error_3d("[[crack]]\nline = { start = [0.006, 0.01, 0.01], end = [0.014, 0.01, 0.01] }\n");
    assert_error(&e, "crack[0].line", Some(19), "a 3D crack is a surface");
    let e = error_with_text(
        "[[crack]]\npenny = { center = [0.01, 0.01], normal = [0.0, 1.0], radius = 0.003 }\n",
    );
    assert_error(&e, "crack[0].penny", Some(19), "a 2D crack is a polyline");
    let e = error_3d(
        "[[crack]]\npenny = { center = [0.01, 0.01, 0.01], normal = [0.0, 0.0, 1.0], radius = 0.003 }\n\
         [fracture]\ncontour = 2\n",
    );
    assert_error(
        &e,
        "fracture.contour",
        Some(21),
        "the square J contour is 2D",
    );
}

/// Two cracks that cross are refused, naming both and the elements that meet; apart,
/// they are accepted.
#[test]
fn crossing_cracks_are_refused() {
    let pennies = |z: f64| {
        format!(
            "[[crack]]\nname = \"a\"\npenny = {{ center = [0.01, 0.01, 0.01], normal = [0.0, 0.0, 1.0], \
             radius = 0.003 }}\n[[crack]]\nname = \"b\"\npenny = {{ center = [0.01, 0.01, {z}], \
             normal = [1.0, 0.0, 0.0], radius = 0.003 }}\n"
        )
    };
    let e = error_3d(&pennies(0.01));
    assert_error(&e, "crack[1]", Some(21), "meets crack `a` (its triangle");
    let e = error_with_text(
        "[[crack]]\nname = \"a\"\nline = { start = [0.006, 0.01], end = [0.014, 0.01] }\n\
         [[crack]]\nline = { start = [0.01, 0.006], end = [0.01, 0.014] }\n",
    );
    assert_error(
        &e,
        "crack[1].line",
        Some(22),
        "meets crack `a` (its segment",
    );
    // On one line or plane the crossing predicates see no crossing; the overlap is refused.
    let e = error_with_text(
        "[[crack]]\nname = \"a\"\nline = { start = [0.006, 0.01], end = [0.012, 0.01] }\n\
         [[crack]]\nline = { start = [0.009, 0.01], end = [0.014, 0.01] }\n",
    );
    assert_error(
        &e,
        "crack[1].line",
        Some(22),
        "meets crack `a` (its segment 0",
    );
    let e = error_3d(
        "[[crack]]\nname = \"a\"\npenny = { center = [0.01, 0.01, 0.01], normal = [0.0, 0.0, 1.0], \
         radius = 0.003 }\n[[crack]]\npenny = { center = [0.012, 0.01, 0.01], \
         normal = [0.0, 0.0, 1.0], radius = 0.003 }\n",
    );
    assert_error(&e, "crack[1]", Some(21), "meets crack `a` (its triangle");
    let src = Source::parse("ok.toml", &text_3d(&pennies(0.0145)), &[]).unwrap();
    assert!(
        fissure::io::scenario::build::<fissure::base::dim::D3>(&src).is_ok(),
        "apart, they are fine"
    );
}

/// Expects along a 3D front: the 2D tip quantities are refused in 3D and the front ones in
/// 2D; a bad `along` or `near` names its key, a crack without a front is refused, and so
/// are compared tubes below 2 cells or set against a main tube of a fractional size.
#[test]
fn bad_front_expects_name_the_key() {
    let penny = "[[crack]]\nname = \"p\"\npenny = { center = [0.01, 0.01, 0.01], \
                 normal = [0.0, 0.0, 1.0], radius = 0.003 }\n[fracture]\n";
    let expect = |q: &str, more: &str| {
        format!(
            "{penny}[[expect]]\nquantity = \"{q}\"\ncrack = \"p\"\nreference = 1.0\n\
             source = \"s\"\ntolerance = 0.1\n{more}"
        )
    };
    let along = |a: &str| format!("along = {{ {a} }}\n");
    let e = error_3d(&expect("KI", ""));
    assert_error(&e, "expect[0].quantity", None, "use KI_front");
    let e = error_3d(&expect(
        "KII_front",
        &along("shape = \"tan\", zero = [1.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0]"),
    ));
    assert_error(&e, "expect[0].along.shape", None, "unknown shape `tan`");
    let e = error_3d(&expect(
        "KII_front",
        &along("shape = \"cos\", zero = [0.0, 0.0, 2.0], normal = [0.0, 0.0, 1.0]"),
    ));
    assert_error(&e, "expect[0].along.zero", None, "parallel");
    let e = error_3d(&expect(
        "KII_front",
        &along("shape = \"cos\", zero = [1.0, 0.0], normal = [0.0, 0.0, 1.0]"),
    ));
    assert_error(&e, "expect[0].along.zero", None, "three components");
    let e = error_3d(&expect(
        "KI_front",
        &along("shape = \"ellipse\", zero = [1.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0]"),
    ));
    assert_error(&e, "expect[0].along.ratio", None, "needs `ratio`");
    let e = error_3d(&expect("KI_front", "tip = \"end\"\n"));
    assert_error(&e, "expect[0].tip", None, "every front vertex");
    let e = error_3d(&expect("KI_front", "near = [0.01, 0.01, 0.019]\n"));
    assert_error(&e, "expect[0].near", None, "within two cells");
    let paths = |fracture: &str, more: &str| {
        expect("J_path", more).replace("[fracture]\n", &format!("[fracture]\n{fracture}"))
    };
    let e = error_3d(&paths("compare = [1]\n", ""));
    assert_error(&e, "fracture.compare", None, "at least 2 cells");
    let e = error_3d(&paths("compare = [4]\ndomain = 2.5\n", ""));
    assert_error(&e, "fracture.domain", None, "whole number of cells");
    let e = error_3d(&paths("compare = [4]\n", "tip = \"end\"\n"));
    assert_error(&e, "expect[0].tip", None, "no named tips");
    let e = error_3d(&paths("compare = [4]\n", "near = [0.0, 0.0, 0.0]\n"));
    assert_error(&e, "expect[0].near", None, "within two cells");
    let rect = text_3d(&expect("KI_front", "").replace(
        "[fracture]\n",
        "[[crack]]\nname = \"r\"\nrectangle = { center = [0.01, 0.01, 0.014], \
         axes = [[0.005, 0.0, 0.0], [0.0, 0.005, 0.0]] }\n[fracture]\n",
    ))
    .replace("crack = \"p\"\nreference", "crack = \"r\"\nreference");
    let src = Source::parse("bad.toml", &rect, &[]).unwrap();
    match fissure::io::scenario::build::<fissure::base::dim::D3>(&src) {
        Ok(_) => panic!("a crack without a front has nothing to measure"),
        Err(e) => assert_error(&e, "expect[0].crack", None, "has no front"),
    }
    let e = error_with_text(
        "[[expect]]\nquantity = \"KI_front\"\ncrack = \"p\"\nreference = 1.0\n\
         source = \"s\"\ntolerance = 0.1\n",
    );
    assert_error(&e, "expect[0].quantity", None, "3D crack front");
    let e = error_with_text(
        "[[expect]]\nquantity = \"momentum_drift\"\nnear = [0.0, 0.0]\n\
         reference = 1.0\nsource = \"s\"\ntolerance = 0.1\n",
    );
    assert_error(&e, "expect[0].near", None, "applies to KI_front");
}

/// Non-finite numbers that used to pass `check` and fail only during the run: a body's spin,
/// a time function's start, a crack expect's reference (TOML's `inf` and `nan`).
#[test]
fn non_finite_numbers_are_refused_at_check() {
    let spin = GOOD.replace("box = { min", "angular_velocity = [inf]\nbox = { min");
    assert_error(&refused(&spin), "body[0].angular_velocity", None, "finite");
    let load = "[[load]]\nregion = { min = [0.004, 0.004], max = [0.006, 0.016] }\n\
                force = [1.0, 0.0]\ntime = { kind = \"step\", start = nan }\n";
    assert_error(&error_with_text(load), "load[0].time", None, "start time");
    let crack = "[[crack]]\npoints = [[0.0, 0.01], [0.01, 0.01]]\n[fracture]\ncontour = 2\n\
                 [[expect]]\nquantity = \"KI\"\ncrack = \"crack0\"\nreference = inf\n\
                 source = \"s\"\ntolerance = 0.1\n";
    assert_error(
        &error_with_text(crack),
        "expect[0].reference",
        None,
        "finite",
    );
}

/// A `--set` that brings in a key the format does not have names the `--set`, not a line
/// past the end of the file (where the override was appended).
#[test]
fn an_unknown_key_from_set_names_the_set() {
    let e = error_with(&["nosuch.key=1"]);
    assert_error(
        &e,
        "nosuch",
        None,
        "(the value comes from --set nosuch.key=1)",
    );
    assert_eq!(e.line, None, "{e}");
}

/// A key a time function does not take is refused in every kind, the constant one too (it
/// used to ignore `rise`).
#[test]
fn a_stray_key_in_a_time_function_is_refused() {
    for time in [
        "{ kind = \"constant\", rise = 1.0 }",
        "{ kind = \"step\", rise = 1.0 }",
    ] {
        let load = format!(
            "[[load]]\nregion = {{ min = [0.004, 0.004], max = [0.006, 0.016] }}\n\
             force = [1.0, 0.0]\ntime = {time}\n"
        );
        let e = error_with_text(&load);
        assert_error(&e, "load[0].time", None, "unknown field `rise`");
    }
}

/// Inputs that used to be accepted although wrong: a name that is not one folder name, two
/// time-step settings, a modulus whose derived quantities overflow, two cracks of one
/// name, a crack that folds back on itself.
#[test]
fn accepted_but_wrong_inputs_are_refused() {
    for (name, words) in [
        ("../../X", "path separator"),
        ("/tmp/X", "path separator"),
        ("", "must not be empty"),
        ("..", "`..`"),
        ("a\\u0007b", "control characters"),
        (&"n".repeat(300), "at most 200 bytes"),
    ] {
        let text = GOOD.replace("name = \"good\"", &format!("name = \"{name}\""));
        let e = match Source::parse("bad.toml", &text, &[]) {
            Err(e) => e,
            Ok(_) => refused(&text),
        };
        assert_error(&e, "name", Some(1), words);
    }
    let e = error_with(&["simulation.dt=1e-9"]);
    assert_error(&e, "simulation.dt", None, "not both");
    let text = GOOD
        .replace("E = 200e9", "E = 1.7e308")
        .replace("rho = 7800.0", "rho = 1e300");
    let e = refused(&text);
    assert_error(&e, "material[0].E", Some(12), "overflow");
    let e = error_with_text(
        "[[crack]]\nname = \"c\"\npoints = [[0.006, 0.01], [0.012, 0.01]]\n\
         [[crack]]\nname = \"c\"\npoints = [[0.006, 0.012], [0.012, 0.012]]\n",
    );
    assert_error(&e, "crack[1].name", Some(22), "two cracks are named `c`");
    let e = error_with_text("[[crack]]\npoints = [[0.006, 0.01], [0.012, 0.01], [0.009, 0.01]]\n");
    assert_error(&e, "crack[0].points", Some(19), "folds back");
}

/// Command-line values that cannot be used exit with code 2: an end time that is not after
/// the start (0, NaN, infinite) or needs too many steps; a resume from a folder without
/// snapshots; a validate over a folder without scenarios (one of a scenario without
/// expects exits 0 and says it ran).
#[test]
fn unusable_command_line_values_exit_with_code_2() {
    let dir = std::env::temp_dir().join(format!("fissure-usage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("good.toml");
    std::fs::write(&file, GOOD).unwrap();
    let fissure = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
            .args(args)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let out = dir.join("out");
    let (f, o) = (file.to_str().unwrap(), out.to_str().unwrap());
    for until in ["0", "NaN", "inf", "1e30"] {
        let (code, err) = fissure(&["run", f, "--out", o, "--until", until]);
        assert_eq!(code, Some(2), "--until {until}: {err}");
        assert!(err.contains("end time"), "{err}");
    }
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let (code, err) = fissure(&["resume", empty.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("no snapshot"), "{err}");
    let (code, err) = fissure(&["validate", empty.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("no scenario"), "{err}");
    // A scenario without expects is not an error, and `validate` says it ran.
    let ran = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
        .args(["validate", f])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&ran.stdout);
    assert_eq!(ran.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("good") && stdout.contains("no [[expect]] to check"),
        "{stdout}"
    );
    // A missing path, a file that is not TOML and a scenario the builder refuses are bad
    // input beside a good scenario too: they exit 2, saying how many were refused.
    let not_toml = dir.join("notes.txt");
    std::fs::write(&not_toml, "not a scenario").unwrap();
    let refused = dir.join("refused.toml");
    std::fs::write(&refused, GOOD.replace("cfl = 0.5", "cfl = 2.0")).unwrap();
    let missing = dir.join("missing.toml");
    for bad in [&missing, &not_toml, &refused] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
            .args(["validate", f, bad.to_str().unwrap()])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(2), "{}: {stdout}", bad.display());
        assert!(stdout.contains("1 refused as bad input"), "{stdout}");
    }
    std::fs::remove_dir_all(dir).ok();
}

/// Asking for more threads than cores caps the pool at the core count with a warning (the
/// workers spin between parallel regions; 1000 of them on 2 cores made no progress).
#[test]
fn more_threads_than_cores_are_capped() {
    let cores = std::thread::available_parallelism().unwrap().get();
    assert_eq!(fissure::app::run::thread_count(1000), cores);
    assert_eq!(fissure::app::run::thread_count(1), 1);
    assert_eq!(fissure::app::run::thread_count(0), cores);
}

/// An error in a value given by `--set` says so instead of pointing at the file's line of
/// the value it replaced; an error in a file value keeps its line.
#[test]
fn errors_in_set_values_name_the_set() {
    let e = error_with(&["material[0].nu=0.7"]);
    assert_error(
        &e,
        "material[0].nu",
        None,
        "comes from --set material[0].nu=0.7",
    );
    assert_eq!(e.line, None, "{e}");
    let e = error_with(&["material.0.E=-1"]);
    assert_error(
        &e,
        "material[0].E",
        None,
        "comes from --set material.0.E=-1",
    );
    let e = error_with(&["simulation.duration=\"long\""]);
    assert_error(&e, "simulation.duration", None, "comes from --set");
    let e = error_with(&["simulation.duration=2e-4", "material[0].nu=0.7"]);
    assert!(e.to_string().contains("--set material[0].nu=0.7"), "{e}");
    let e = error_with(&["simulation.duration=2e-4", "grid.cell=[0.0, 0.002]"]);
    assert!(!e.to_string().contains("--set simulation"), "{e}");
}

/// A crack cut finer than any use (1e-12 m spacing) is refused at once instead of
/// building 1e10 vertices; a long, finely cut crack is checked for self-crossing in about
/// linear time, and a crossing near its end is still found and named by its segments.
#[test]
fn crack_vertex_counts_are_bounded_and_checked_fast() {
    let e = error_with_text(
        "[[crack]]\nline = { start = [0.006, 0.01], end = [0.014, 0.01], spacing = 1e-12 }\n",
    );
    assert_error(&e, "crack[0].line.spacing", Some(19), "more than 100000");
    // 3D surfaces are counted before they are meshed: a penny at 1e-9 m took 152 s and
    // 1.6 GB to generate, the same at 1e-4 m is 600 triangles.
    for (shape, key) in [
        (
            "penny = { center = [0.01, 0.01, 0.01], normal = [0.0, 0.0, 1.0], radius = 0.003",
            "penny",
        ),
        (
            "rectangle = { center = [0.01, 0.01, 0.01], axes = [[0.003, 0.0, 0.0], [0.0, 0.003, 0.0]]",
            "rectangle",
        ),
        (
            "ellipse = { center = [0.01, 0.01, 0.01], axes = [[0.003, 0.0, 0.0], [0.0, 0.002, 0.0]]",
            "ellipse",
        ),
    ] {
        let e = error_3d(&format!("[[crack]]\n{shape}, spacing = 1e-9 }}\n"));
        assert_error(
            &e,
            &format!("crack[0].{key}.spacing"),
            Some(19),
            "more than 200000",
        );
    }
    // 40,000 points along a fine zigzag inside the body (1e-7 m high, so no fold), then a
    // turn down and a last segment back up across it: that segment passes through the
    // zigzag's band between x = 9.9995 and 10.0003 mm, segments 19997 to 20001, and the
    // first crossing in index order is with segment 19998 (every pair of segments is 8e9
    // tests).
    let mut pts: Vec<String> = (0..40_000)
        .map(|k| {
            let x = 0.006 + 0.008 * k as f64 / 40_000.0;
            let y = 0.01 + if k % 2 == 0 { 0.0 } else { 1e-7 };
            format!("[{x:e}, {y:e}]")
        })
        .collect();
    let fine = format!("[[crack]]\npoints = [{}]\n", pts.join(", "));
    let src = Source::parse("bad.toml", &format!("{GOOD}{fine}"), &[]).unwrap();
    assert!(build::<D2>(&src).is_ok(), "a long fine crack is accepted");
    pts.push("[0.014, 0.0095]".into());
    pts.push("[0.0060005, 0.0105]".into());
    let crossed = format!("[[crack]]\npoints = [{}]\n", pts.join(", "));
    let e = error_with_text(&crossed);
    assert_error(
        &e,
        "crack[0].points",
        Some(19),
        "crosses itself (segments 19998 and 40000)",
    );
}

/// More material tables than a particle's material index can name are refused by their
/// count before anything is built from them.
#[test]
fn too_many_materials_are_refused_by_count() {
    let mut text = GOOD.to_string();
    for k in 0..65_536 {
        text += &format!("[[material]]\nname = \"m{k}\"\nE = 1e9\nnu = 0.3\nrho = 1000.0\n");
    }
    let e = refused(&text);
    assert_error(&e, "material", None, "65537 materials: at most 65535");
}

#[test]
fn bad_growth_tables_name_the_key() {
    let crack = "[[crack]]\npoints = [[0.003, 0.01], [0.009, 0.01]]\n[crack.growth]\n";
    let fracture = "[fracture]\ncontour = 2\n";
    let with = |growth: &str| error_with_text(&format!("{crack}{growth}{fracture}"));
    let e = with("initiation = \"hoop\"\nKIc = -2e6\n");
    assert_error(&e, "crack[0].growth.KIc", Some(22), "must be positive");
    let e = with("initiation = \"energy\"\n");
    assert_error(&e, "crack[0].growth.initiation", Some(21), "needs `Gc`");
    let e = with("initiation = \"hoop\"\nKIc = 2e6\nGc = 20.0\n");
    assert_error(&e, "crack[0].growth.Gc", Some(23), "does not apply");
    let e = with("initiation = \"time\"\nat = 0.0\nextension = 1e-6\n");
    assert_error(&e, "crack[0].growth.extension", Some(23), "0.01 to 2 cells");
    let e = with("initiation = \"time\"\nat = 0.0\nextension = 0.005\n");
    assert_error(&e, "crack[0].growth.extension", Some(23), "0.01 to 2 cells");
    let e = with("initiation = \"time\"\nat = 0.0\ninterval = 1e-12\n");
    assert_error(&e, "crack[0].growth.interval", Some(23), "one time step");
    let e = with("initiation = \"time\"\nat = 0.0\nspeed = 1e5\n");
    assert_error(&e, "crack[0].growth.speed", Some(23), "Rayleigh");
    let e = with("initiation = \"time\"\nat = 0.0\nparis = { C = 1e-29, m = 0.0 }\n");
    assert_error(
        &e,
        "crack[0].growth.paris.m",
        Some(23),
        "exponent must be positive",
    );
    let e = with("initiation = \"time\"\nat = 0.0\nparis = { C = -1.0, m = 3.0 }\n");
    assert_error(&e, "crack[0].growth.paris.C", Some(23), "must be positive");
    let e = with("initiation = \"time\"\nat = 0.0\nparis = { C = 1e-29, m = 3.0, R = 1.0 }\n");
    assert_error(&e, "crack[0].growth.paris.R", Some(23), "[0, 1)");
    let e = with("initiation = \"hoop\"\nKIc = 2e6\nparis = { C = 1e-29, m = 3.0 }\n");
    assert_error(&e, "crack[0].growth.initiation", Some(21), "set time");
    let e = with("initiation = \"time\"\nat = 0.0\ntoughness = 2e6\n");
    assert_error(&e, "crack[0].growth.toughness", Some(23), "unknown field");
    let e = error_with_text(&format!("{crack}initiation = \"hoop\"\nKIc = 2e6\n"));
    assert_error(&e, "crack[0].growth", None, "add a [fracture] table");
    let e = error_with_text(&format!(
        "{crack}initiation = \"time\"\nat = 0.0\n{fracture}[[expect]]\nquantity = \"cycles\"\n\
         crack = \"crack0\"\nlength = 1e-3\nreference = 1.0\nsource = \"x\"\ntolerance = 0.1\n"
    ));
    assert_error(&e, "expect[0].quantity", None, "no `paris`");
    // A 3D front turns by the hoop stress only where K is measured, does not run at a set
    // speed, and its cycles are the front's, not a tip's.
    let penny = "[[crack]]\npenny = { center = [0.01, 0.01, 0.01], normal = [0.0, 0.0, 1.0], \
                 radius = 0.003 }\n[crack.growth]\ninitiation = \"time\"\nat = 0.0\n";
    let e = error_3d(&format!("{penny}direction = \"hoop\"\n"));
    assert_error(&e, "crack[0].growth", None, "add a [fracture] table");
    let e = error_3d(&format!("{penny}speed = 100.0\n"));
    assert_error(&e, "crack[0].growth.speed", None, "set speed");
    let e = error_3d(&format!(
        "{penny}paris = {{ C = 1e-29, m = 3.0 }}\n[fracture]\ndomain = 2\n[[expect]]\nquantity = \"cycles\"\n\
         crack = \"crack0\"\ntip = \"end\"\nlength = 1e-3\nreference = 1.0\nsource = \"x\"\n\
         tolerance = 0.1\n"
    ));
    assert_error(&e, "expect[0].tip", None, "along its front");
    let e = error_3d(&format!(
        "{penny}[fracture]\ndomain = 2\n[[expect]]\nquantity = \"path_angle\"\ncrack = \"crack0\"\n\
         reference = 1.0\nsource = \"x\"\ntolerance = 0.1\n"
    ));
    assert_error(&e, "expect[0].quantity", None, "2D tip");
    let e = error_3d(
        "[[crack]]\nrectangle = { center = [0.01, 0.01, 0.01], axes = [[0.003, 0.0, 0.0], \
         [0.0, 0.0, 0.003]] }\n[crack.growth]\ninitiation = \"time\"\nat = 0.0\n",
    );
    assert_error(&e, "crack[0].growth", None, "no front to grow");
}

/// GOOD with `keys` added to its material (from line 15 on).
fn plastic_steel(keys: &str) -> String {
    GOOD.replace("rho = 7800.0\n", &format!("rho = 7800.0\n{keys}"))
}

#[test]
fn bad_plasticity_parameters_name_the_key() {
    let j2 = "model = \"j2\"\n";
    let cases: [(String, &str, usize, &str); 10] = [
        (j2.into(), "material[0].model", 15, "sigma_y"),
        (
            format!("{j2}sigma_y = -1.0\n"),
            "material[0].sigma_y",
            16,
            "positive",
        ),
        (
            format!("{j2}sigma_y = 30e9\n"),
            "material[0].sigma_y",
            16,
            "yield strain",
        ),
        (
            format!("{j2}sigma_y = 250e6\nH = -1e9\n"),
            "material[0].H",
            17,
            "zero or positive",
        ),
        (
            format!("{j2}sigma_y = 250e6\nn = 1.0\n"),
            "material[0].n",
            17,
            "1 < n",
        ),
        (
            format!("{j2}sigma_y = 250e6\nn = 10\nH = 1e9\n"),
            "material[0].n",
            17,
            "not both",
        ),
        (
            "sigma_y = 250e6\n".into(),
            "material[0].sigma_y",
            15,
            "model = \"j2\"",
        ),
        (
            format!("{j2}sigma_y = 250e6\nn = 10\nalpha = -1.0\n"),
            "material[0].alpha",
            18,
            "positive",
        ),
        (
            format!("{j2}sigma_y = 250e6\nalpha = 1.0\n"),
            "material[0].alpha",
            17,
            "exponent",
        ),
        (
            "alpha = 1.0\n".into(),
            "material[0].alpha",
            15,
            "model = \"j2\"",
        ),
    ];
    for (keys, key, line, words) in cases {
        assert_error(&refused(&plastic_steel(&keys)), key, Some(line), words);
    }
    let e = Source::parse("bad.toml", &plastic_steel("model = \"tresca\"\n"), &[]).unwrap_err();
    assert_eq!(e.line, Some(15), "{e}");
    assert!(
        e.to_string().contains("tresca") && e.to_string().contains("j2"),
        "{e}"
    );
}

#[test]
fn bad_time_tables_name_the_key() {
    let load = |points: &str| {
        format!(
            "[[load]]\nregion = {{ min = [0.004, 0.004], max = [0.006, 0.016] }}\n\
             force = [1.0, 0.0]\ntime = {{ kind = \"table\", points = {points} }}\n"
        )
    };
    for (points, words) in [
        ("[]", "at least one"),
        ("[[0.0, 0.0], [0.0, 1.0]]", "strictly increasing"),
        ("[[1e-5, 0.0], [0.5e-5, 1.0]]", "strictly increasing"),
    ] {
        let e = refused(&format!("{GOOD}{}", load(points)));
        assert_error(&e, "load[0].time", Some(21), words);
    }
}

#[test]
fn opening_probe_needs_both_sides() {
    // One column of particles (x = 4.5 mm): none lies beyond the centroid along x.
    let probe = "[[probe]]\nname = \"cmod\"\nregion = { min = [0.004, 0.004], max = [0.0049, 0.016] }\n\
                 quantity = \"opening\"\ncomponent = \"x\"\n";
    let e = refused(&format!("{GOOD}{probe}"));
    assert_error(&e, "probe[0].region", Some(20), "both sides");
}

/// A plastic radius needs a plastic material and a disc region, and has no component;
/// every other probe needs its component.
#[test]
fn plastic_radius_probes_are_checked() {
    let probe = |region: &str, extra: &str| {
        format!(
            "[[probe]]\nname = \"zone\"\nregion = {region}\nquantity = \"plastic_radius\"\n{extra}"
        )
    };
    let disc = "{ center = [0.01, 0.01], radius = 0.005 }";
    let plastic = plastic_steel("model = \"j2\"\nsigma_y = 250e6\nH = 0.0\n");
    let e = refused(&format!("{GOOD}{}", probe(disc, "")));
    assert_error(&e, "probe[0].quantity", None, "plastic material");
    let e = refused(&format!(
        "{plastic}{}",
        probe("{ min = [0.004, 0.004], max = [0.016, 0.016] }", "")
    ));
    assert_error(&e, "probe[0].region", None, "disc or ball");
    let e = refused(&format!("{plastic}{}", probe(disc, "component = \"x\"\n")));
    assert_error(&e, "probe[0].component", None, "no component");
    let e = refused(&format!(
        "{GOOD}[[probe]]\nname = \"u\"\nregion = {disc}\nquantity = \"displacement\"\n"
    ));
    assert_error(&e, "probe[0].component", None, "give the probed component");
}

/// A scene may hold more than 32 cracks, but no more than 32 within reach of one another:
/// the 33rd of a row 0.1 mm apart is refused, naming it.
#[test]
fn too_many_cracks_in_one_place_are_refused() {
    let mut text = GOOD.to_string();
    for k in 0..40 {
        let x = 0.006 + 1e-4 * k as f64;
        text += &format!(
            "[[crack]]\nname = \"c{k}\"\npoints = [[{x:.4}, 0.0071], [{x:.4}, 0.0089]]\ntips = []\n"
        );
    }
    let e = refused(&text);
    assert_error(&e, "crack[32]", None, "crack `c32` lies within reach");
    let spread: String = (0..40)
        .map(|k| {
            let x = 0.0041 + 3e-4 * k as f64;
            format!("[[crack]]\npoints = [[{x:.4}, 0.0045], [{x:.4}, 0.0047]]\ntips = []\n")
        })
        .collect();
    let wide = GOOD.replace("cell = [0.002, 0.002]", "cell = [0.00005, 0.00005]");
    assert!(build::<D2>(&Source::parse("ok.toml", &(wide + &spread), &[]).unwrap()).is_ok());
}

#[test]
fn bad_reactions_and_eta_estimates_name_the_key() {
    let support =
        "[[boundary]]\nregion = { min = [0.0, 0.0], max = [0.004, 0.02] }\nfix = [\"x\"]\n";
    let probe = |region: &str, component: &str| {
        format!(
            "[[probe]]\nname = \"load\"\nregion = {region}\nquantity = \"reaction\"\ncomponent = \"{component}\"\n"
        )
    };
    let left = "{ min = [0.0, 0.0], max = [0.004, 0.02] }";
    let e = error_with_text(&format!("{support}{}", probe(left, "y")));
    assert_error(&e, "probe[0].region", None, "prescribes its component");
    let e = error_with_text(&format!(
        "{support}{}",
        probe("{ min = [0.01, 0.0], max = [0.02, 0.02] }", "x")
    ));
    assert_error(
        &e,
        "probe[0].region",
        None,
        "no grid node of a [[boundary]]",
    );
    let crack = "[[crack]]\npoints = [[0.003, 0.01], [0.01, 0.01]]\n[fracture]\n";
    let displacement = "[[probe]]\nname = \"d\"\nregion = { min = [0.014, 0.004], max = [0.016, 0.016] }\nquantity = \"displacement\"\ncomponent = \"x\"\n";
    let eta = "eta = { factor = 1.9, ligament = 0.006, K_per_load = 50.0, material = \"steel\" }\n";
    let expect = |body: &str| {
        error_with_text(&format!(
            "{support}{}{displacement}{crack}[[expect]]\ncrack = \"crack0\"\nreference = 0.0\nsource = \"s\"\ntolerance = 0.05\n{body}",
            probe(left, "x")
        ))
    };
    let e = expect("quantity = \"J_eta\"\nprobes = [\"load\", \"d\"]\n");
    assert_error(&e, "expect[0].eta", None, "give the specimen's estimate");
    let e = expect(&format!("quantity = \"J_eta\"\nprobes = [\"load\"]\n{eta}"));
    assert_error(&e, "expect[0].probes", None, "takes two probes");
    let e = expect(&format!(
        "quantity = \"J_eta\"\nprobes = [\"load\", \"d\"]\n{}",
        eta.replace("1.9", "-1.9")
    ));
    assert_error(
        &e,
        "expect[0].eta.factor",
        None,
        "must be a positive number",
    );
    let e = expect(&format!(
        "quantity = \"J_eta\"\nprobes = [\"load\", \"d\"]\n{}",
        eta.replace("\"steel\"", "\"iron\"")
    ));
    assert_error(
        &e,
        "expect[0].eta.material",
        None,
        "no [[material]] named `iron`",
    );
    let e = expect(&format!("quantity = \"KI\"\n{eta}"));
    assert_error(&e, "expect[0].eta", None, "applies to J_eta");
    let e = expect("quantity = \"KI\"\nprobes = [\"d\"]\n");
    assert_error(&e, "expect[0].probes", None, "takes no probes");
}

/// What is not a scenario file is refused before it is read: a FIFO (whose open would
/// block), a device (whose read never ends), a file too large to be a scenario; and a
/// scenario without `name` whose file stem is not a folder name (`..toml`) is refused as a
/// bad name would be. `check` and `resume` of a FIFO answer at once with exit code 2.
#[test]
fn files_that_are_not_scenarios_are_refused_before_reading() {
    let dir = std::env::temp_dir().join(format!("fissure-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let load = |p: &std::path::Path| match Source::load(p, &[]) {
        Ok(_) => panic!("{} was read as a scenario", p.display()),
        Err(e) => e.to_string(),
    };
    let e = load(std::path::Path::new("/dev/zero"));
    assert!(e.contains("not a regular file"), "{e}");
    let big = dir.join("big.toml");
    std::fs::write(&big, " ".repeat(17 << 20)).unwrap();
    let e = load(&big);
    assert!(e.contains("at most 16777216"), "{e}");
    let dots = dir.join("..toml");
    std::fs::write(&dots, GOOD.replace("name = \"good\"\n", "")).unwrap();
    let e = match build::<D2>(&Source::load(&dots, &[]).unwrap()) {
        Ok(_) => panic!("a stem of `.` names no folder"),
        Err(e) => e,
    };
    assert!(e.to_string().contains("file's stem `.`"), "{e}");
    let fifo = dir.join("fifo.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        for verb in ["check", "resume"] {
            let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_fissure"))
                .args([verb, fifo.to_str().unwrap()])
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap();
            let t0 = std::time::Instant::now();
            let status = loop {
                if let Some(s) = child.try_wait().unwrap() {
                    break Some(s);
                }
                if t0.elapsed().as_secs() > 20 {
                    child.kill().ok();
                    break None;
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            };
            let status = status.unwrap_or_else(|| panic!("`{verb}` of a FIFO blocked"));
            assert_eq!(status.code(), Some(2), "{verb}");
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

/// On quadratic B-splines a plane boundary is a symmetry plane whose nodes past it mirror
/// the body's side: one that holds a tangential component, moves, or has the body on both
/// sides is refused at its key, with the line in the file although `--set` added a line
/// above it; a plane at the body's edge builds, with image nodes, and on uGIMP the
/// refused planes build as before.
#[test]
fn a_b_spline_plane_that_is_not_a_symmetry_plane_is_refused() {
    let build_with = |shape: &str, plane: &str| {
        let text = format!("{GOOD}[[boundary]]\n{plane}\n");
        let set = vec![format!("simulation.shape=\"{shape}\"")];
        build::<D2>(&Source::parse("bad.toml", &text, &set).unwrap())
    };
    let edge = "plane = { axis = \"x\", at = 0.004 }";
    let world = build_with("bspline", edge).unwrap().world;
    // One column of nodes a cell past the plane and one two cells past, each 11 nodes high.
    assert_eq!(world.grid.mirrors.images.len(), 22);
    let cases = [
        (
            "plane = { axis = \"x\", at = 0.01 }",
            "boundary[0].plane",
            "both sides",
        ),
        (
            "plane = { axis = \"x\", at = 0.004 }\nfix = [\"x\", \"y\"]",
            "boundary[0].fix",
            "normal component only",
        ),
        (
            "plane = { axis = \"x\", at = 0.004 }\nvelocity = [0.1, 0.0]",
            "boundary[0].velocity",
            "at rest",
        ),
    ];
    for (plane, key, words) in cases {
        assert!(build_with("ugimp", plane).is_ok(), "{plane}");
        match build_with("bspline", plane) {
            Ok(_) => panic!("{plane}: must be refused on B-splines"),
            Err(e) => assert_error(&e, key, None, words),
        }
    }
    match build_with("bspline", "plane = { axis = \"x\", at = 0.01 }") {
        Err(e) => assert_eq!(e.line, Some(19), "{e}"),
        Ok(_) => unreachable!(),
    }
}
