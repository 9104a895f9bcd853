//! The documentation against the code: every key the scenario parser accepts is named in
//! docs/scenario-format.md, and every TOML example in docs/ parses and builds.

use fissure::io::scenario::{Source, build};
use std::path::Path;

/// Tables of the scenario format, each with a shipped scenario that holds it: the parser
/// is asked for the keys of each by giving it one it does not know.
const TABLES: &[(&str, &str)] = &[
    ("scenarios/dcb_2d.toml", ""),
    ("scenarios/dcb_2d.toml", "simulation."),
    ("scenarios/dcb_2d.toml", "grid."),
    ("scenarios/centre_crack_2d.toml", "grid.anchor."),
    ("scenarios/centre_crack_2d.toml", "crack[0].line."),
    ("scenarios/dcb_rotated_2d.toml", "body[0].polygon."),
    ("scenarios/long/sphere_plastic_3d.toml", "body[0].sphere."),
    ("scenarios/dcb_2d.toml", "load[0].region."),
    ("scenarios/dcb_2d.toml", "load[0].time."),
    ("scenarios/dcb_2d.toml", "material[0]."),
    ("scenarios/dcb_2d.toml", "body[0]."),
    ("scenarios/dcb_2d.toml", "body[0].box."),
    ("scenarios/dcb_2d.toml", "crack[0]."),
    ("scenarios/dcb_2d.toml", "crack[0].contact."),
    ("scenarios/dcb_2d.toml", "boundary[0]."),
    ("scenarios/dcb_2d.toml", "load[0]."),
    ("scenarios/bar_plastic_2d.toml", "probe[0]."),
    ("scenarios/long/ellipse_rod_3d.toml", "expect[0].along."),
    ("scenarios/dcb_2d.toml", "output."),
    ("scenarios/dcb_2d.toml", "checkpoint."),
    ("scenarios/dcb_2d.toml", "fracture."),
    ("scenarios/dcb_2d.toml", "expect[0]."),
    ("scenarios/disks_2d.toml", "body[0].disc."),
    ("scenarios/bar_static_2d.toml", "boundary[0].plane."),
    ("scenarios/inclined_growth_2d.toml", "crack[0].growth."),
    (
        "scenarios/long/paris_edge_2d.toml",
        "crack[0].growth.paris.",
    ),
    ("scenarios/cylinder_plastic_2d.toml", "load[0].pressure."),
    ("scenarios/williams_2d.toml", "load[0].williams."),
    ("scenarios/centre_crack_2d.toml", "load[0].centre_crack."),
    ("scenarios/senb_plastic_2d.toml", "expect[0].eta."),
    ("scenarios/long/penny_3d.toml", "crack[0].penny."),
    ("scenarios/long/ellipse_rod_3d.toml", "crack[0].ellipse."),
    ("scenarios/long/cylinder_surface_3d.toml", "crack[0].mesh."),
    (
        "scenarios/long/cylinder_surface_3d.toml",
        "body[0].cylinder.",
    ),
];

/// The keys the parser lists for an unknown one: "expected one of `a`, `b`", "expected `a`
/// or `b`", or "expected `a`".
fn expected_keys(message: &str) -> Vec<String> {
    let Some((_, tail)) = message.split_once("expected ") else {
        return Vec::new();
    };
    let list = tail.split(" (the value comes from").next().unwrap_or(tail);
    list.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// Whether `doc` names `key` as a word of its own.
fn names(doc: &str, key: &str) -> bool {
    doc.match_indices(key).any(|(i, _)| {
        let word = |c: char| c.is_ascii_alphanumeric() || c == '_';
        let before = doc[..i].chars().next_back().is_none_or(|c| !word(c));
        let after = doc[i + key.len()..].chars().next().is_none_or(|c| !word(c));
        before && after
    })
}

#[test]
fn every_key_the_parser_accepts_is_in_the_scenario_format_chapter() {
    let doc = std::fs::read_to_string("docs/scenario-format.md").expect("the chapter");
    let mut checked = 0;
    let mut missing = Vec::new();
    for (file, table) in TABLES {
        let set = format!("{table}zz_not_a_key=1");
        let err = match Source::load(Path::new(file), std::slice::from_ref(&set)) {
            Ok(_) => panic!("{file}: --set {set} was accepted"),
            Err(e) => e.to_string(),
        };
        let keys = expected_keys(&err);
        assert!(!keys.is_empty(), "{file} {table}: no key list in `{err}`");
        for key in keys {
            checked += 1;
            if !names(&doc, &key) {
                missing.push(format!("{table}{key}"));
            }
        }
    }
    assert!(
        checked > 150,
        "only {checked} keys were listed by the parser"
    );
    assert!(
        missing.is_empty(),
        "keys the parser accepts but docs/scenario-format.md does not name: {missing:?}"
    );
}

#[test]
fn every_toml_example_in_the_docs_builds() {
    let mut examples = 0;
    for entry in std::fs::read_dir("docs").expect("docs/") {
        let path = entry.expect("a docs entry").path();
        if path.extension().is_none_or(|e| e != "md") {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("a chapter");
        for block in text.split("```toml\n").skip(1) {
            let body = block.split("\n```").next().expect("a closed block");
            examples += 1;
            let src = Source::parse(&path.display().to_string(), body, &[])
                .unwrap_or_else(|e| panic!("{}: an example does not parse: {e}", path.display()));
            let built = match src.scenario.simulation.dimension {
                2 => build::<fissure::base::dim::D2>(&src).map(|_| ()),
                _ => build::<fissure::base::dim::D3>(&src).map(|_| ()),
            };
            built.unwrap_or_else(|e| panic!("{}: an example does not build: {e}", path.display()));
        }
    }
    assert!(examples >= 1, "no TOML example found in docs/");
}
