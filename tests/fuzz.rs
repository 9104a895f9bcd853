//! The scenario parser and builder never panic: on arbitrary bytes; on the shipped
//! scenarios (the long ones too: 3D crack meshes, growth, fatigue, plasticity, regions)
//! with bytes deleted, replaced, inserted or lines repeated; with numbers replaced by
//! extreme ones (0, negative, tiny, huge, NaN, infinities); and under random `--set`
//! and `--vary` arguments. They either build the scene or return an error, each case
//! within a bounded time. 64 cases each by default; PROPTEST_CASES=20000 for a longer
//! fuzzing session.

use fissure::app::sweep::{Vary, combinations, run_count};
use fissure::base::dim::{D2, D3};
use fissure::io::scenario::{Source, build};
use proptest::prelude::*;
use std::sync::OnceLock;

/// The texts of the shipped scenarios, in `scenarios/` and `scenarios/long/`.
fn shipped() -> &'static [String] {
    static TEXTS: OnceLock<Vec<String>> = OnceLock::new();
    TEXTS.get_or_init(|| {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
        let mut paths: Vec<_> = [root.clone(), root.join("long")]
            .iter()
            .flat_map(|dir| std::fs::read_dir(dir).unwrap())
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        paths.sort();
        paths
            .iter()
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect()
    })
}

/// Longest a case may take to parse and build (s): the builder's work is bounded by the
/// grid-size guard below, so a case past this is work growing without bound (a generous
/// limit, for a loaded 2-core machine).
const CASE_SECONDS: u64 = 30;

/// Parses `text` with `overrides` and, when its grid is small enough to build in a
/// moment, builds it, in at most [`CASE_SECONDS`].
fn parse_and_build(text: &str, overrides: &[String]) {
    let start = std::time::Instant::now();
    build_small(text, overrides);
    let took = start.elapsed().as_secs();
    assert!(
        took < CASE_SECONDS,
        "a case took {took} s: {overrides:?}\n{text}"
    );
}

fn build_small(text: &str, overrides: &[String]) {
    let Ok(src) = Source::parse("fuzz.toml", text, overrides) else {
        return;
    };
    let g = &src.scenario.grid;
    let nodes: f64 = (g.min.iter().zip(&g.max).zip(&g.cell))
        .map(|((lo, hi), h)| ((hi - lo) / h).abs() + 1.0)
        .product();
    // Mutations can ask for huge scenes, which the builder accepts while they fit in
    // memory; only small ones are built here, to keep the test quick.
    if !(nodes.is_finite() && nodes < 2e5) {
        return;
    }
    let _ = match src.scenario.simulation.dimension {
        3 => build::<D3>(&src).map(|_| ()),
        _ => build::<D2>(&src).map(|_| ()),
    };
}

/// Numbers a mutation puts in place of one in the text: the edges of what a key accepts.
const EXTREMES: [&str; 12] = [
    "0",
    "-1",
    "-0.0",
    "1e-300",
    "1e300",
    "nan",
    "inf",
    "-inf",
    "0.5",
    "3",
    "-1e-9",
    "9007199254740993",
];

/// `text` with its `k`-th number (counted modulo how many there are) replaced by `by`.
fn replace_number(text: &str, k: usize, by: &str) -> String {
    let b = text.as_bytes();
    let starts: Vec<usize> = (0..b.len())
        .filter(|&i| {
            b[i].is_ascii_digit()
                && (i == 0
                    || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'))
        })
        .collect();
    let Some(&i) = starts.get(k % starts.len().max(1)) else {
        return text.to_string();
    };
    let end = (i..b.len())
        .find(|&j| !(b[j].is_ascii_alphanumeric() || b"+-._".contains(&b[j])))
        .unwrap_or(b.len());
    format!("{}{by}{}", &text[..i], &text[end..])
}

/// Keys a `--set` override may name: the tables and keys of the scenario format, some
/// misspelt, and array entries past the end.
const KEYS: [&str; 21] = [
    "simulation.dimension",
    "simulation.duration",
    "simulation.cfl",
    "simulation.dt",
    "simulation.damping",
    "simulation.shape",
    "grid.cell",
    "grid.min",
    "grid.max",
    "material[0].E",
    "material[0].nu",
    "material[0].rho",
    "body[0].material",
    "crack[0].growth.paris.m",
    "fracture.domain",
    "fracture.k_from",
    "output.interval",
    "checkpoint.every_steps",
    "material[7].E",
    "simulaton.duration",
    "body[0].mesh.file",
];

/// Values a `--set` override may give.
const VALUES: [&str; 15] = [
    "0",
    "-1",
    "1e300",
    "nan",
    "inf",
    "\"ugimp\"",
    "\"x\"",
    "[0.001, 0.001]",
    "[1, 2, 3]",
    "{ kind = \"ramp\" }",
    "true",
    "[]",
    "1e-9",
    "",
    "\"part.stl\"",
];

/// One edit of `text` at the fraction `at` of its length: 0 deletes up to `len` bytes,
/// 1 replaces one byte by `byte`, 2 inserts `chunk`, 3 repeats the line there.
fn mutate(text: &str, op: u8, at: f64, len: usize, byte: u8, chunk: &str) -> String {
    let mut b = text.as_bytes().to_vec();
    let i = ((b.len() as f64 * at) as usize).min(b.len().saturating_sub(1));
    match op {
        0 => {
            let end = (i + len).min(b.len());
            b.drain(i..end);
        }
        1 => {
            if !b.is_empty() {
                b[i] = byte;
            }
        }
        2 => {
            b.splice(i..i, chunk.bytes());
        }
        _ => {
            let start = b[..i]
                .iter()
                .rposition(|&c| c == b'\n')
                .map_or(0, |k| k + 1);
            let end = b[i..]
                .iter()
                .position(|&c| c == b'\n')
                .map_or(b.len(), |k| i + k + 1);
            let line = b[start..end].to_vec();
            b.splice(start..start, line);
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(64)
    ))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2048)) {
        parse_and_build(&String::from_utf8_lossy(&bytes), &[]);
    }

    #[test]
    fn mutated_scenarios_never_panic(
        which in any::<usize>(),
        edits in proptest::collection::vec(
            (0u8..4, 0.0f64..1.0, 1usize..40, any::<u8>(), "[ -~\n]{0,24}"),
            1..6,
        ),
    ) {
        let texts = shipped();
        let mut text = texts[which % texts.len()].clone();
        for (op, at, len, byte, chunk) in &edits {
            text = mutate(&text, *op, *at, *len, *byte, chunk);
        }
        parse_and_build(&text, &[]);
    }

    #[test]
    fn extreme_numbers_never_panic(
        which in any::<usize>(),
        edits in proptest::collection::vec((any::<usize>(), 0..EXTREMES.len()), 1..4),
    ) {
        let texts = shipped();
        let mut text = texts[which % texts.len()].clone();
        for (k, v) in &edits {
            text = replace_number(&text, *k, EXTREMES[*v]);
        }
        parse_and_build(&text, &[]);
    }

    #[test]
    fn vary_arguments_never_panic(
        which in any::<usize>(),
        args in proptest::collection::vec(
            (0..KEYS.len(), proptest::collection::vec(0..VALUES.len(), 0..4), "[=,\\[\\]{}\"' a-z0-9.]{0,12}"),
            1..3,
        ),
    ) {
        let texts = shipped();
        let mut vary = Vec::new();
        for (k, values, noise) in &args {
            let list: Vec<&str> = values.iter().map(|&v| VALUES[v]).collect();
            let arg = format!("{}={}{noise}", KEYS[*k], list.join(","));
            if let Ok(v) = Vary::parse(&arg) {
                vary.push(v);
            }
        }
        if run_count(&vary).is_some_and(|n| n <= 8) {
            for set in combinations(&vary) {
                parse_and_build(&texts[which % texts.len()], &set);
            }
        }
    }

    #[test]
    fn random_overrides_never_panic(
        which in any::<usize>(),
        sets in proptest::collection::vec((0..KEYS.len(), 0..VALUES.len()), 1..4),
    ) {
        let texts = shipped();
        let overrides: Vec<String> = sets
            .iter()
            .map(|&(k, v)| format!("{}={}", KEYS[k], VALUES[v]))
            .collect();
        parse_and_build(&texts[which % texts.len()], &overrides);
    }
}
