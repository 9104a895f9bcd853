//! Parameter sweeps: a scenario run over the grid of values of one or more keys, each run
//! a row of sweep.csv (its values, size, cost and every expect's value and error), so
//! error can be read against cost. A sweep stopped part-way resumes: the rows already in
//! sweep.csv are not run again.

use crate::app::run::stop::StopFlag;
use crate::app::run::{RunOptions, run};
use crate::base::error::UsageError;
use crate::io::output::plot::{self, Series};
use crate::io::output::summary::Status;
use crate::io::output::summary::Summary;
use crate::io::scenario::Source;
use anyhow::Context;
use std::io::Write;
use std::path::Path;

/// How a sweep ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Swept {
    /// Every combination has its row in sweep.csv.
    Complete,
    /// A stop was asked for: the rows of the runs that finished are in sweep.csv, the run
    /// that was stopped has none, and sweeping again runs what is missing.
    Stopped,
}

/// Most runs a sweep makes without being told `--yes`.
pub const MAX_RUNS: usize = 1000;

/// Most runs a sweep makes at all: every combination's scenario is loaded and kept before
/// the first run, so that a bad value anywhere is refused up front.
pub const MAX_RUNS_EVER: usize = 10_000;

/// The run's columns of sweep.csv, after the varied keys and before the expects' value,
/// error and pass.
const RUN_COLUMNS: [&str; 7] = [
    "status",
    "particles",
    "nodes",
    "steps",
    "wall_seconds",
    "particle_steps_per_second",
    "bytes_per_particle",
];

/// The column of the wall time in a row of `keys` varied keys.
fn wall_column(keys: usize) -> usize {
    keys + 4
}

/// The column of expect `k`'s error in a row of `keys` varied keys.
fn error_column(keys: usize, k: usize) -> usize {
    keys + RUN_COLUMNS.len() + 3 * k + 1
}

/// One swept key and its values, as `--set` takes them (TOML values).
#[derive(Clone, Debug, PartialEq)]
pub struct Vary {
    /// Dotted key, e.g. `grid.cell`.
    pub key: String,
    /// Its values, in order.
    pub values: Vec<String>,
}

impl Vary {
    /// Parses `KEY=V1,V2,...`; commas inside brackets, braces or quotes belong to a value
    /// (`grid.cell=[2e-3, 2e-3],[1e-3, 1e-3]`).
    pub fn parse(arg: &str) -> Result<Vary, UsageError> {
        let bad = |why: &str| UsageError(format!("--vary {arg}: {why}"));
        let (key, list) = arg
            .split_once('=')
            .ok_or_else(|| bad("give KEY=V1,V2,..."))?;
        let key = key.trim();
        if key.is_empty() {
            return Err(bad("the key is empty"));
        }
        let values = split_values(list).map_err(|why| bad(&why))?;
        if values.iter().any(String::is_empty) {
            return Err(bad(
                "a value is empty (give at least one, separated by commas)",
            ));
        }
        Ok(Vary {
            key: key.to_string(),
            values,
        })
    }
}

/// Splits a value list at the commas outside brackets, braces and quotes.
fn split_values(list: &str) -> Result<Vec<String>, String> {
    let (mut out, mut cur, mut depth, mut quote) = (Vec::new(), String::new(), 0i32, None);
    for ch in list.chars() {
        match (quote, ch) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(ch),
            (None, '[' | '{') => depth += 1,
            (None, ']' | '}') => depth -= 1,
            (None, ',') if depth == 0 => {
                out.push(cur.trim().to_string());
                cur.clear();
                continue;
            }
            _ => {}
        }
        if depth < 0 {
            return Err("a closing bracket has no opening one".into());
        }
        cur.push(ch);
    }
    if depth != 0 || quote.is_some() {
        return Err("a bracket or quote is not closed".into());
    }
    out.push(cur.trim().to_string());
    Ok(out)
}

/// How many runs the sweep of `vary` has (the product of the value counts), None past
/// `usize`.
pub fn run_count(vary: &[Vary]) -> Option<usize> {
    vary.iter()
        .try_fold(1usize, |n, v| n.checked_mul(v.values.len()))
}

/// Every combination of the values, the first key varying slowest, as `--set` arguments.
pub fn combinations(vary: &[Vary]) -> Vec<Vec<String>> {
    vary.iter().fold(vec![Vec::new()], |acc, v| {
        acc.iter()
            .flat_map(|prefix| {
                v.values.iter().map(move |value| {
                    let mut c = prefix.clone();
                    c.push(format!("{}={value}", v.key));
                    c
                })
            })
            .collect()
    })
}

/// The header of sweep.csv: the varied keys, the run's figures, then value, error and
/// pass of each expect (named by quantity and crack or probes).
pub fn header(vary: &[Vary], expects: &[String]) -> String {
    let mut cols: Vec<String> = vary.iter().map(|v| v.key.clone()).collect();
    cols.extend(RUN_COLUMNS.map(String::from));
    for e in expects {
        cols.extend([
            format!("{e} value"),
            format!("{e} error"),
            format!("{e} pass"),
        ]);
    }
    cols.iter().map(|c| quote(c)).collect::<Vec<_>>().join(",")
}

/// One run's row of sweep.csv: `values` are the varied keys' values in order.
pub fn row(values: &[String], summary: &Summary) -> String {
    let mut cols: Vec<String> = values.iter().map(|v| quote(v)).collect();
    cols.extend([
        summary.status.to_string(),
        summary.particles.to_string(),
        summary.nodes.to_string(),
        summary.steps.to_string(),
        format!("{:.6e}", summary.wall_seconds),
        format!("{:.6e}", summary.particle_steps_per_second),
        summary.bytes_per_particle.to_string(),
    ]);
    for e in &summary.expects {
        let num = |v: Option<f64>| v.map_or("NaN".into(), |v| format!("{v:.9e}"));
        cols.extend([num(e.value), num(e.error), e.pass.to_string()]);
    }
    cols.join(",")
}

/// The row of a run that did not finish (unstable, or refused at set-up): its status,
/// and empty figures and expects.
pub fn failed_row(values: &[String], status: &str, expects: usize) -> String {
    let mut cols: Vec<String> = values.iter().map(|v| quote(v)).collect();
    cols.push(status.to_string());
    cols.extend(std::iter::repeat_n(
        String::new(),
        RUN_COLUMNS.len() - 1 + 3 * expects,
    ));
    cols.join(",")
}

/// A CSV field: quoted when it holds a comma or a quote.
fn quote(s: &str) -> String {
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The varied values of the rows already in `csv` (a sweep resuming), after checking that
/// its header is `header`; an empty list when there is no such file. Rows of runs refused
/// at set-up (status `error`: a setting the scenario could not take, perhaps fixed since)
/// are dropped from the file, so that those runs are tried again.
pub fn done(csv: &Path, header: &str, keys: usize) -> Result<Vec<Vec<String>>, UsageError> {
    let Ok(text) = std::fs::read_to_string(csv) else {
        return Ok(Vec::new());
    };
    let mut lines = text.lines();
    if lines.next() != Some(header) {
        return Err(UsageError(format!(
            "{} belongs to another sweep (other keys or expects): give another --out",
            csv.display()
        )));
    }
    let (kept, refused): (Vec<&str>, Vec<&str>) = lines
        .filter(|l| !l.is_empty())
        .partition(|l| fields(l).get(keys).is_none_or(|s| s != "error"));
    if !refused.is_empty() {
        let text: String = std::iter::once(header)
            .chain(kept.iter().copied())
            .map(|l| format!("{l}\n"))
            .collect();
        std::fs::write(csv, text)
            .map_err(|e| UsageError(format!("cannot rewrite {}: {e}", csv.display())))?;
    }
    Ok(kept
        .iter()
        .map(|l| fields(l).into_iter().take(keys).collect())
        .collect())
}

/// The fields of a CSV line written by [`row`] (quotes undone).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted, mut chars) =
        (Vec::new(), String::new(), false, line.chars());
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.clone().next() == Some('"') => {
                chars.next();
                cur.push('"');
            }
            (true, '"') => quoted = false,
            (false, '"') => quoted = true,
            (false, ',') => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// How one run of a sweep went, for the launcher's progress line.
pub struct Ran<'a> {
    /// 1-based index of the run and the number of runs.
    pub index: (usize, usize),
    /// The `--set` arguments of the run.
    pub set: &'a [String],
    /// Its summary, when it finished (completed or not).
    pub summary: Option<&'a Summary>,
    /// Why it did not finish, if it did not; "already in sweep.csv" for a skipped run.
    pub error: Option<String>,
}

/// Runs `file` over every combination of `vary` on `threads` threads, appending a row per
/// run to `<out>/sweep.csv` and telling `progress` about each. Every combination is loaded
/// (so a bad key or value is refused) before the first run; more than [`MAX_RUNS`] runs
/// need `yes`. Setting `stop` stops the run under way at its next step and the sweep after
/// it, that run leaving no row.
pub fn sweep(
    file: &Path,
    vary: &[Vary],
    threads: usize,
    out: &Path,
    yes: bool,
    stop: Option<StopFlag>,
    mut progress: impl FnMut(&Ran),
) -> anyhow::Result<Swept> {
    if vary.is_empty() {
        return Err(UsageError("give at least one --vary KEY=V1,V2,...".into()).into());
    }
    for (k, v) in vary.iter().enumerate() {
        if vary[..k].iter().any(|w| w.key == v.key) {
            return Err(UsageError(format!("--vary {} is given twice", v.key)).into());
        }
    }
    // Counted before the combinations are built: five keys of 100 values each are 1e10.
    let runs = run_count(vary).filter(|&n| n <= MAX_RUNS_EVER);
    let Some(runs) = runs else {
        let n: f64 = vary.iter().map(|v| v.values.len() as f64).product();
        return Err(UsageError(format!(
            "the sweep has {n:.3e} runs, more than the {MAX_RUNS_EVER} a sweep can hold: \
             give fewer --vary values, or split it into several sweeps"
        ))
        .into());
    };
    if runs > MAX_RUNS && !yes {
        return Err(UsageError(format!(
            "the sweep has {runs} runs, more than {MAX_RUNS}: add --yes to run them all"
        ))
        .into());
    }
    let combos = combinations(vary);
    let sources = (combos.iter())
        .map(|set| Source::load(file, set))
        .collect::<Result<Vec<_>, _>>()?;
    let specs = &sources[0].scenario.expects;
    let mut expects: Vec<String> = (specs.iter())
        .map(|e| {
            let names: Vec<&str> = (e.crack.iter().chain(&e.tip).chain(&e.probes))
                .map(String::as_str)
                .collect();
            format!("{} {}", e.quantity, names.join("/"))
                .trim()
                .to_string()
        })
        .collect();
    // Two expects of one quantity at one place (against two references) are told apart
    // by their references.
    let repeated: Vec<bool> = (expects.iter())
        .map(|e| expects.iter().filter(|f| *f == e).count() > 1)
        .collect();
    for ((e, spec), twice) in expects.iter_mut().zip(specs).zip(repeated) {
        if twice {
            *e = format!("{e} (reference {:e})", spec.reference);
        }
    }
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output folder {}", out.display()))?;
    let csv = out.join("sweep.csv");
    let head = header(vary, &expects);
    let done = done(&csv, &head, vary.len())?;
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&csv)
        .with_context(|| format!("cannot open {}", csv.display()))?;
    let named = |e: std::io::Error| anyhow::anyhow!("cannot write {}: {e}", csv.display());
    if done.is_empty() && file.metadata().map_err(named)?.len() == 0 {
        writeln!(file, "{head}").map_err(named)?;
    }
    let n = combos.len();
    let stopped = || stop.as_ref().is_some_and(StopFlag::is_asked);
    let mut swept = Swept::Complete;
    for (k, (set, src)) in combos.iter().zip(sources).enumerate() {
        if stopped() {
            swept = Swept::Stopped;
            break;
        }
        let values: Vec<String> = (set.iter())
            .map(|a| a.split_once('=').map_or("", |(_, v)| v).to_string())
            .collect();
        let index = (k + 1, n);
        if done.contains(&values) {
            progress(&Ran {
                index,
                set,
                summary: None,
                error: Some("already in sweep.csv".into()),
            });
            continue;
        }
        let opts = RunOptions {
            threads,
            stop: stop.clone(),
            ..RunOptions::default()
        };
        match run(&src, &opts) {
            Ok(o) if o.summary.status == Status::Interrupted => {
                swept = Swept::Stopped;
                break;
            }
            Ok(o) => {
                // One write per row, so that a kill leaves whole lines.
                let line = format!("{}\n", row(&values, &o.summary));
                file.write_all(line.as_bytes()).map_err(named)?;
                progress(&Ran {
                    index,
                    set,
                    summary: Some(&o.summary),
                    error: None,
                });
            }
            Err(e) => {
                let status = if e.to_string().contains("unstable") {
                    "unstable"
                } else {
                    "error"
                };
                let line = format!("{}\n", failed_row(&values, status, expects.len()));
                file.write_all(line.as_bytes()).map_err(named)?;
                progress(&Ran {
                    index,
                    set,
                    summary: None,
                    error: Some(format!("{e:#}")),
                });
            }
        }
        file.flush().map_err(named)?;
    }
    plots(&csv, vary, &expects, out)?;
    Ok(swept)
}

/// sweep_<k>.png for expect k: its error against wall time on log-log axes, every row of
/// sweep.csv (this invocation's and earlier ones'), one curve per value of the first
/// varied key when more than one key varies.
fn plots(csv: &Path, vary: &[Vary], expects: &[String], out: &Path) -> anyhow::Result<()> {
    let text =
        std::fs::read_to_string(csv).with_context(|| format!("cannot read {}", csv.display()))?;
    let rows: Vec<Vec<String>> = text.lines().skip(1).map(fields).collect();
    let keys = vary.len();
    let number = |r: &[String], k: usize| r.get(k).and_then(|v| v.parse::<f64>().ok());
    let groups: Vec<String> = if keys > 1 {
        vary[0].values.clone()
    } else {
        vec![String::new()]
    };
    for (k, e) in expects.iter().enumerate() {
        let series: Vec<Series> = (groups.iter())
            .map(|g| Series {
                label: if keys > 1 { g } else { "runs" },
                points: (rows.iter())
                    .filter(|r| keys == 1 || r.first() == Some(g))
                    .filter_map(|r| {
                        Some((
                            number(r, wall_column(keys))?,
                            number(r, error_column(keys, k))?,
                        ))
                    })
                    .collect(),
            })
            .collect();
        let title = if keys > 1 {
            format!("{e}: error against cost, by {}", vary[0].key)
        } else {
            format!("{e}: error against cost over {}", vary[0].key)
        };
        let path = out.join(format!("sweep_{k}.png"));
        plot::log_log(&path, &title, "wall time (s)", "error", &series)
            .map_err(|why| anyhow::anyhow!("cannot draw {}: {why}", path.display()))?;
    }
    if let Some(c) = vary.iter().position(|v| v.key == "grid.cell") {
        convergence(&rows, vary, c, expects, out)?;
    }
    Ok(())
}

/// sweep_<k>_cell.png when `grid.cell` (key `c`) is swept: expect k's error against the
/// cell size on log-log axes, one curve per setting of the other keys (those given one
/// value are the same on every curve and left out of the labels), with the fitted order
/// of convergence in its label.
fn convergence(
    rows: &[Vec<String>],
    vary: &[Vary],
    c: usize,
    expects: &[String],
    out: &Path,
) -> anyhow::Result<()> {
    let keys = vary.len();
    let others = |r: &[String]| -> String {
        (0..keys)
            .filter(|&j| j != c && vary[j].values.len() > 1)
            .map(|j| format!("{}={}", vary[j].key, r.get(j).map_or("", String::as_str)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut groups: Vec<String> = Vec::new();
    for r in rows {
        let g = others(r);
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    for (k, e) in expects.iter().enumerate() {
        let mut labels = Vec::new();
        let mut points = Vec::new();
        for g in &groups {
            let pts: Vec<(f64, f64)> = (rows.iter())
                .filter(|r| &others(r) == g)
                .filter_map(|r| {
                    let h = cell_size(r.get(c)?)?;
                    Some((h, r.get(error_column(keys, k))?.parse().ok()?))
                })
                .collect();
            let fit = order(&pts).map_or("no order".into(), |p| format!("order {p:.2}"));
            let name = if g.is_empty() { "runs" } else { g };
            labels.push(format!("{name} ({fit})"));
            points.push(pts);
        }
        let series: Vec<Series> = (labels.iter().zip(points))
            .map(|(label, points)| Series { label, points })
            .collect();
        let path = out.join(format!("sweep_{k}_cell.png"));
        let title = format!("{e}: error against cell size");
        plot::log_log(&path, &title, "cell size (m)", "error", &series)
            .map_err(|why| anyhow::anyhow!("cannot draw {}: {why}", path.display()))?;
    }
    Ok(())
}

/// The first cell size of a `grid.cell` value (`[2e-3, 2e-3]` gives 2e-3).
fn cell_size(value: &str) -> Option<f64> {
    let inner = value.trim().trim_start_matches('[');
    inner.split([',', ']']).next()?.trim().parse().ok()
}

/// The order of convergence p of error ~ h^p: the least-squares slope of ln(error)
/// against ln(h) over the points with both positive; None with fewer than two sizes.
pub fn order(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = (points.iter())
        .filter(|(h, e)| *h > 0.0 && *e > 0.0 && h.is_finite() && e.is_finite())
        .map(|(h, e)| (h.ln(), e.ln()))
        .collect();
    let n = logs.len() as f64;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (logs.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lists keep their commas; combinations run the first key slowest; a row's quoted
    /// values read back as they were.
    #[test]
    fn values_combinations_and_rows() {
        let v = Vary::parse("grid.cell=[2e-3, 2e-3],[1e-3, 1e-3]").unwrap();
        assert_eq!(v.values, vec!["[2e-3, 2e-3]", "[1e-3, 1e-3]"]);
        let s = Vary::parse("simulation.shape=\"linear\",\"ugimp\"").unwrap();
        let c = combinations(&[v, s]);
        assert_eq!(c.len(), 4);
        assert_eq!(
            c[1],
            vec!["grid.cell=[2e-3, 2e-3]", "simulation.shape=\"ugimp\""]
        );
        assert!(Vary::parse("grid.cell").is_err());
        assert!(Vary::parse("grid.cell=").is_err());
        assert!(Vary::parse("grid.cell=[1e-3,1e-3").is_err());
        assert!(Vary::parse("a=1,,2").is_err());
        let values = vec!["[2e-3, 2e-3]".to_string(), "\"ugimp\"".to_string()];
        let line = failed_row(&values, "unstable", 1);
        assert_eq!(
            fields(&line)[..3],
            ["[2e-3, 2e-3]", "\"ugimp\"", "unstable"]
        );
        assert_eq!(fields(&line).len(), 3 + 6 + 3);
    }

    /// The fitted order of a power law is its exponent; one size gives none.
    #[test]
    fn order_of_convergence() {
        let pts: Vec<(f64, f64)> = [4e-3, 2e-3, 1e-3]
            .iter()
            .map(|&h| (h, 3.0 * h * h))
            .collect();
        assert!((order(&pts).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(order(&pts[..1]), None);
        assert_eq!(cell_size("[2e-3, 2e-3]"), Some(2e-3));
        assert_eq!(cell_size("5e-4"), Some(5e-4));
    }
}
