//! The run's figures: energy.png (energies and the balance's drift), fracture.png (K over
//! time at 2D tips, or along 3D fronts at the end) and growth.png (crack paths or fronts).

use super::plot::{self, Panel, Series};
use crate::base::dim::Dim;
use crate::base::geometry::Element;
use crate::fracture::plan::TipResult;
use crate::record::expect::{Expect, Measure};
use crate::record::history::{History, Row, balance_drift};
use crate::store::crack::Cracks;
use std::path::Path;

/// What the figures of a run draw from besides its history.
pub struct Figures<'a, D: Dim> {
    /// Scenario name, for the titles.
    pub name: &'a str,
    /// The run's expects (their K references are drawn with K).
    pub expects: &'a [Expect],
    /// Crack names, when J and K were measured.
    pub crack_names: Option<&'a [String]>,
    /// The scale K is drawn over (K0), when given.
    pub k0: Option<f64>,
    /// The cracks at the end of the run, when some crack grows.
    pub grown: Option<&'a Cracks<D>>,
}

impl<D: Dim> Figures<'_, D> {
    /// Draws every figure the run has into `dir`.
    pub fn draw(&self, dir: &Path, h: &History) -> anyhow::Result<()> {
        plot_energies(&dir.join("energy.png"), self.name, h)
            .map_err(|e| anyhow::anyhow!("cannot draw energy.png: {e}"))?;
        if let Some(cracks) = self.crack_names {
            let path = dir.join("fracture.png");
            let drawn = if D::D == 3 {
                plot_front(&path, self.name, h, cracks, self.k0)
            } else {
                plot_fracture(&path, self.name, h, self.expects, cracks, self.k0)
            };
            drawn.map_err(|e| anyhow::anyhow!("cannot draw fracture.png: {e}"))?;
        }
        if let Some(cracks) = self.grown {
            plot_paths(&dir.join("growth.png"), self.name, cracks)
                .map_err(|e| anyhow::anyhow!("cannot draw growth.png: {e}"))?;
        }
        Ok(())
    }
}

/// K_I and K_II over time at every tip, with each K expect's reference (a flat line, or a
/// curve through the references at given times); divided by `k0` when given. When a crack
/// grows, a panel below draws the crack lengths.
fn plot_fracture(
    path: &Path,
    name: &str,
    h: &History,
    expects: &[Expect],
    cracks: &[String],
    k0: Option<f64>,
) -> Result<(), String> {
    let scale = 1.0 / k0.unwrap_or(1.0);
    let mut tips: Vec<(u32, u32)> = h.fracture.iter().map(|t| (t.crack, t.tip)).collect();
    tips.sort_unstable();
    tips.dedup();
    let t_end = h.fracture.last().map_or(0.0, |t| t.time);
    let label =
        |c: u32, tip: u32| format!("{} {}", cracks[c as usize], ["start", "end"][tip as usize]);
    let mut labels = Vec::new();
    let mut points = Vec::new();
    for &(c, tip) in &tips {
        for (k, mode) in ["KI", "KII"].iter().enumerate() {
            labels.push(format!("{mode} {}", label(c, tip)));
            points.push(
                h.fracture
                    .iter()
                    .filter(|t| (t.crack, t.tip) == (c, tip))
                    .map(|t| (t.time, t.k[k] * scale))
                    .collect::<Vec<_>>(),
            );
        }
    }
    // A reference for the last value is a level line; references at times join up into a
    // curve, one per crack tip and quantity.
    for e in expects {
        let Measure::Tip {
            crack,
            tip,
            qty,
            at,
        } = e.measure
        else {
            continue;
        };
        if qty >= 2 {
            continue;
        }
        let name = format!("{} reference {}", e.quantity, label(crack, tip));
        match at {
            None => {
                labels.push(name);
                points.push(vec![
                    (0.0, e.reference * scale),
                    (t_end, e.reference * scale),
                ]);
            }
            Some(t) => match labels.iter().position(|l| *l == name) {
                Some(k) => points[k].push((t, e.reference * scale)),
                None => {
                    labels.push(name);
                    points.push(vec![(t, e.reference * scale)]);
                }
            },
        }
    }
    let title = format!("{name}: stress intensity factors");
    if h.growth.is_empty() {
        return k_plot(path, &title, "time (s)", &labels, points, k0);
    }
    // A growing crack: its length below K, on the same time axis.
    let length_labels: Vec<String> = (tips.iter())
        .map(|&(c, tip)| format!("length {}", label(c, tip)))
        .collect();
    let lengths = (tips.iter())
        .map(|&(c, tip)| {
            (h.fracture.iter())
                .filter(|t| (t.crack, t.tip) == (c, tip))
                .map(|t| (t.time, t.length))
                .collect()
        })
        .collect();
    let axis = k_axis(k0);
    let panels = [
        Panel {
            y_label: &axis,
            series: series(&labels, points),
        },
        Panel {
            y_label: "crack length (m)",
            series: series(&length_labels, lengths),
        },
    ];
    plot::panels(path, &title, "time (s)", &panels, 0.62)
}

/// Draws K series (over `k0` when given, which the y axis then says) into a PNG.
fn k_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    labels: &[String],
    points: Vec<Vec<(f64, f64)>>,
    k0: Option<f64>,
) -> Result<(), String> {
    let series = series(labels, points);
    plot::lines(path, title, x_label, &k_axis(k0), &series)
}

/// The K axis's label: K, or K over `k0` when given.
fn k_axis(k0: Option<f64>) -> String {
    match k0 {
        Some(k0) => format!("K / K0 (K0 = {k0:.4e} Pa sqrt(m))"),
        None => "K (Pa sqrt(m))".to_string(),
    }
}

/// Series from labels and their points.
fn series(labels: &[String], points: Vec<Vec<(f64, f64)>>) -> Vec<Series<'_>> {
    (labels.iter().zip(points))
        .map(|(l, p)| Series {
            label: l,
            points: p,
        })
        .collect()
}

/// K_I, K_II and K_III along every 3D crack front at the last measurement, against the
/// front vertex's ordinal; divided by `k0` when given.
fn plot_front(
    path: &Path,
    name: &str,
    h: &History,
    cracks: &[String],
    k0: Option<f64>,
) -> Result<(), String> {
    let scale = 1.0 / k0.unwrap_or(1.0);
    let last = h.fracture.last().map_or(0, |t| t.step);
    let rows: Vec<&TipResult> = h.fracture.iter().filter(|t| t.step == last).collect();
    let mut labels = Vec::new();
    let mut points = Vec::new();
    for (c, crack) in cracks.iter().enumerate() {
        for (k, mode) in ["KI", "KII", "KIII"].iter().enumerate() {
            labels.push(format!("{mode} {crack}"));
            points.push(
                (rows.iter())
                    .filter(|t| t.crack as usize == c)
                    .map(|t| (f64::from(t.tip), t.k[k] * scale))
                    .collect::<Vec<_>>(),
            );
        }
    }
    let time = rows.first().map_or(0.0, |t| t.time);
    k_plot(
        path,
        &format!("{name}: K along the front at {time:.4e} s"),
        "front vertex",
        &labels,
        points,
        k0,
    )
}

/// growth.png: every growing crack's path (its whole polyline) at the end of the run; in
/// 3D its fronts at the end, seen along the global axis nearest its mean normal.
fn plot_paths<D: Dim>(path: &Path, name: &str, cracks: &Cracks<D>) -> Result<(), String> {
    let topo = &cracks.topology;
    let x = &cracks.geometry.x;
    let growing = |c: usize| topo.cracks()[c].growth.is_some();
    if D::D == 2 {
        let series: Vec<Series> = (topo.cracks().iter())
            .filter(|c| c.growth.is_some())
            .map(|c| Series {
                label: &c.name,
                points: (c.vertices.iter())
                    .map(|&v| {
                        let p = D::to_xyz(x[v as usize]);
                        (p[0], p[1])
                    })
                    .collect(),
            })
            .collect();
        return plot::plane(
            path,
            &format!("{name}: crack paths"),
            ["x (m)", "y (m)"],
            &series,
        );
    }
    // The axis the cracks face most: the largest component of their summed area normals.
    let mut normal = [0.0f64; 3];
    for (e, &c) in topo.elems().iter().zip(topo.elem_crack()) {
        if growing(c as usize) {
            let n = D::to_xyz(e.normal(x));
            (0..3).for_each(|a| normal[a] += n[a].abs());
        }
    }
    let facing = (0..3).fold(0, |b, a| if normal[a] > normal[b] { a } else { b });
    let axes = [(facing + 1) % 3, (facing + 2) % 3];
    let series: Vec<Series> = (topo.fronts().iter())
        .filter(|f| growing(f.crack as usize))
        .map(|f| {
            let ring = f.vertices.first().filter(|_| topo.is_closed(f));
            Series {
                label: &topo.cracks()[f.crack as usize].name,
                points: (f.vertices.iter().chain(ring))
                    .map(|&v| {
                        let p = D::to_xyz(x[v as usize]);
                        (p[axes[0]], p[axes[1]])
                    })
                    .collect(),
            }
        })
        .collect();
    let label = |a: usize| ["x (m)", "y (m)", "z (m)"][a];
    plot::plane(
        path,
        &format!("{name}: crack fronts at the end"),
        [label(axes[0]), label(axes[1])],
        &series,
    )
}

/// energy.png: the energies and works on top; below, the energy balance's drift
/// (E(t) - E(0)) over the largest energy or work of the run, the scale `energy_drift`
/// uses, so a drift too small to see on the energies' scale still shows.
fn plot_energies(path: &Path, name: &str, h: &History) -> Result<(), String> {
    let pick = |f: &dyn Fn(&Row) -> f64| h.rows.iter().map(|r| (r.time, f(r))).collect();
    let mut energies = Panel {
        y_label: "energy (J)",
        series: vec![
            Series {
                label: "kinetic K",
                points: pick(&|r| r.energies.kinetic),
            },
            Series {
                label: "strain W",
                points: pick(&|r| r.energies.strain),
            },
            Series {
                label: "external work W_ext",
                points: pick(&|r| r.energies.external_work),
            },
            Series {
                label: "damping work W_damp",
                points: pick(&|r| r.energies.damping_work),
            },
        ],
    };
    if h.rows.iter().any(|r| r.energies.plastic_work != 0.0) {
        energies.series.push(Series {
            label: "plastic work W_p",
            points: pick(&|r| r.energies.plastic_work),
        });
    }
    if h.rows.iter().any(|r| r.energies.friction_work != 0.0) {
        energies.series.push(Series {
            label: "friction work W_f",
            points: pick(&|r| r.energies.friction_work),
        });
    }
    let balance = Panel {
        y_label: "balance drift (relative)",
        series: vec![Series {
            label: "(K + W + W_p - W_ext + W_damp + W_f - E(0)) / largest energy or work",
            points: balance_drift(h).unwrap_or_default(),
        }],
    };
    plot::panels(
        path,
        &format!("{name}: energies"),
        "time (s)",
        &[energies, balance],
        0.62,
    )
}
