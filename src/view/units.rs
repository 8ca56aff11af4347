//! Display units and signs of history columns in plots and reports: lengths in mm, forces
//! in kN, stresses in MPa, vertical displacements positive down and forces shown with the
//! sign that makes their largest value positive, chosen from the monitor kinds that
//! `summary.json` lists (docs/view.md, "Units and signs"). `--units si` and `--sign raw`
//! keep the file's SI values.

use std::path::Path;

/// How to show history values.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UnitOptions {
    /// Keep the SI units of history.csv (m, N, Pa) instead of mm, kN, MPa.
    pub si: bool,
    /// Keep the recorded signs (no deflection-positive-down, no flipped forces).
    pub raw_sign: bool,
}

/// What a monitor is, as summary.json describes it.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Kind {
    /// Input kind (`displacement`, `reaction`, …; `control_force` for that column).
    pub kind: String,
    /// Component (`x`, `y`, `sx`, …), if any.
    pub component: Option<String>,
}

/// A column as shown: shown value = `factor` × file value.
#[derive(Debug, Clone, PartialEq)]
pub struct Shown {
    /// Scale and sign applied to the file's values.
    pub factor: f64,
    /// Display unit (`mm`, `kN`, `MPa`, or the file's unit).
    pub unit: String,
    /// Axis label: name, sign note and unit, e.g. `midspan_uy, down [mm]`.
    pub label: String,
}

/// Display unit and scale of an SI unit: m → mm, N → kN, Pa → MPa, N·m → kN·m; others kept.
pub fn display_unit(si: &str) -> (&str, f64) {
    match si {
        "m" => ("mm", 1e3),
        "N" => ("kN", 1e-3),
        "Pa" => ("MPa", 1e-6),
        "N·m" | "Nm" => ("kN·m", 1e-3),
        u => (u, 1.0),
    }
}

/// How to show the column `name` in `unit` with `values`, of monitor kind `kind` (None when
/// unknown: units only, no sign change).
pub fn shown(
    name: &str,
    unit: &str,
    kind: Option<&Kind>,
    values: &[f64],
    opts: UnitOptions,
) -> Shown {
    let (unit, scale) = if opts.si {
        (unit, 1.0)
    } else {
        display_unit(unit)
    };
    let kind_is = |k: &str| kind.is_some_and(|c| c.kind == k);
    let vertical = kind.is_some_and(|c| c.component.as_deref() == Some("y"));
    let (sign, note) = if opts.raw_sign {
        (1.0, "")
    } else if kind_is("displacement") && vertical {
        // Deflection positive down, as engineers draw load–deflection curves.
        (-1.0, ", down")
    } else if kind_is("reaction") || kind_is("control_force") {
        // A force of a downward load reads positive.
        let big = values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(0.0);
        if big < 0.0 {
            (-1.0, ", sign reversed")
        } else {
            (1.0, "")
        }
    } else {
        (1.0, "")
    };
    let label = if unit.is_empty() {
        format!("{name}{note}")
    } else {
        format!("{name}{note} [{unit}]")
    };
    Shown {
        factor: sign * scale,
        unit: unit.to_string(),
        label,
    }
}

/// Panel of each column: columns sharing a unit share a panel (and its y axis), in the
/// order the units first appear.
pub fn group_by_unit(units: &[String]) -> Vec<usize> {
    let mut seen: Vec<&str> = Vec::new();
    units
        .iter()
        .map(|u| match seen.iter().position(|s| s == u) {
            Some(i) => i,
            None => {
                seen.push(u);
                seen.len() - 1
            }
        })
        .collect()
}

/// Monitor kinds of a run, read from `<dir>/summary.json` (`monitors`), plus
/// `control_force`; empty when the file is absent or older than the `monitors` list.
pub fn kinds(dir: &Path) -> Vec<(String, Kind)> {
    let v: serde_json::Value = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(serde_json::Value::Null);
    let mut out: Vec<(String, Kind)> = v["monitors"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|m| {
                    Some((
                        m["name"].as_str()?.to_string(),
                        Kind {
                            kind: m["kind"].as_str()?.to_string(),
                            component: m["component"].as_str().map(str::to_string),
                        },
                    ))
                })
                .collect()
        })
        .unwrap_or_default();
    out.push((
        "control_force".into(),
        Kind {
            kind: "control_force".into(),
            component: None,
        },
    ));
    out
}

/// What a unit load factor stands for, read from `<dir>/summary.json`: per load case of
/// forces only (point and edge loads; no gravity, no temperature) with a non-zero
/// resultant, the magnitude of that resultant at factor 1 [N]; and the load case of each
/// `load_factor` monitor. Empty for runs older than these lists.
#[derive(Debug, Clone, Default)]
pub struct FactorUnits {
    /// (load case name, |resultant at factor 1| [N]).
    pub cases: Vec<(String, f64)>,
    /// (monitor name, load case name) of the `load_factor` monitors.
    pub monitors: Vec<(String, String)>,
}

impl FactorUnits {
    /// Read from `<dir>/summary.json` (`load_cases`, `monitors[].case`).
    pub fn read(dir: &Path) -> FactorUnits {
        let v: serde_json::Value = std::fs::read_to_string(dir.join("summary.json"))
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or(serde_json::Value::Null);
        let cases = v["load_cases"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter(|c| c["forces_only"].as_bool() == Some(true))
                    .filter_map(|c| {
                        let r = c["resultant"].as_array()?;
                        let (x, y) = (r.first()?.as_f64()?, r.get(1)?.as_f64()?);
                        let f = x.hypot(y);
                        (f > 0.0).then(|| (c["name"].as_str().unwrap_or("").to_string(), f))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let monitors = v["monitors"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|m| {
                        Some((
                            m["name"].as_str()?.to_string(),
                            m["case"].as_str()?.to_string(),
                        ))
                    })
                    .collect()
            })
            .unwrap_or_default();
        FactorUnits { cases, monitors }
    }

    /// The load case whose factor the column `name` holds: `factor:<case>`, or the case
    /// of a `load_factor` monitor.
    pub fn case_of<'a>(&'a self, name: &'a str) -> Option<&'a str> {
        name.strip_prefix("factor:").or_else(|| {
            self.monitors
                .iter()
                .find(|(m, _)| m == name)
                .map(|(_, c)| c.as_str())
        })
    }

    /// The force [N] a unit factor of the column `name` stands for, if its load case is
    /// one of forces only.
    pub fn force_of(&self, name: &str) -> Option<f64> {
        let case = self.case_of(name)?;
        self.cases.iter().find(|(c, _)| c == case).map(|(_, f)| *f)
    }

    /// `s` for the column `name` with the unit of its load case: a factor of a case of
    /// forces only reads `Q [× 2 kN total]` (the resultant at factor 1 in the display unit,
    /// 4 significant digits); other columns unchanged.
    pub fn apply(&self, name: &str, s: Shown, opts: UnitOptions) -> Shown {
        let Some(f) = self.force_of(name) else {
            return s;
        };
        let (unit, scale) = if opts.si {
            ("N", 1.0)
        } else {
            display_unit("N")
        };
        let mut v = super::figures::sig4(f * scale);
        if v.contains('.') && !v.contains('e') {
            // 2.000 → 2: the resultant is a round number more often than not.
            v = v.trim_end_matches('0').trim_end_matches('.').to_string();
        }
        let unit = format!("× {v} {unit} total");
        let base = s.label.rsplit_once(" [").map_or(s.label.as_str(), |l| l.0);
        Shown {
            factor: s.factor,
            label: format!("{base} [{unit}]"),
            unit,
        }
    }
}

/// Region names of a run (summary.json `regions`); empty when absent.
pub fn region_names(dir: &Path) -> Vec<String> {
    names(dir, "regions")
}

/// Joint names of a run (summary.json `joints`); empty when absent.
pub fn joint_names(dir: &Path) -> Vec<String> {
    names(dir, "joints")
}

/// A list of names in summary.json.
fn names(dir: &Path, key: &str) -> Vec<String> {
    std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| {
            v[key].as_array().map(|a| {
                a.iter()
                    .map(|r| r.as_str().unwrap_or("").to_string())
                    .collect()
            })
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn k(kind: &str, c: Option<&str>) -> Kind {
        Kind {
            kind: kind.into(),
            component: c.map(str::to_string),
        }
    }

    #[test]
    fn units_and_signs_follow_the_kind() {
        let o = UnitOptions::default();
        let d = shown("mid", "m", Some(&k("displacement", Some("y"))), &[-0.01], o);
        assert_eq!((d.factor, d.unit.as_str()), (-1e3, "mm"));
        assert_eq!(d.label, "mid, down [mm]");
        // A horizontal displacement keeps its sign.
        let d = shown("ux", "m", Some(&k("displacement", Some("x"))), &[-0.01], o);
        assert_eq!(d.factor, 1e3);
        // Opening: mm, sign kept.
        let d = shown("open", "m", Some(&k("joint_opening", None)), &[0.002], o);
        assert_eq!((d.factor, d.label.as_str()), (1e3, "open [mm]"));
        // A control force pulling down reads positive, in kN.
        let f = shown("F", "N", Some(&k("control_force", None)), &[-1.0, -5e3], o);
        assert_eq!((f.factor, f.unit.as_str()), (-1e-3, "kN"));
        let r = shown("R", "N", Some(&k("reaction", Some("y"))), &[1.0, 5e3], o);
        assert_eq!(r.factor, 1e-3);
        let s = shown("s", "Pa", Some(&k("stress", Some("sx"))), &[-3e6], o);
        assert_eq!((s.factor, s.unit.as_str()), (1e-6, "MPa"));
        let l = shown("Q", "-", Some(&k("load_factor", None)), &[3.0], o);
        assert_eq!((l.factor, l.label.as_str()), (1.0, "Q [-]"));
        // Unknown kind: units only.
        let u = shown("u", "m", None, &[-1.0], o);
        assert_eq!(u.factor, 1e3);
        // Overrides.
        let si = UnitOptions {
            si: true,
            raw_sign: true,
        };
        let d = shown(
            "mid",
            "m",
            Some(&k("displacement", Some("y"))),
            &[-0.01],
            si,
        );
        assert_eq!((d.factor, d.label.as_str()), (1.0, "mid [m]"));
    }

    #[test]
    fn one_panel_per_unit() {
        let u = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(
            group_by_unit(&u(&["kN", "mm", "kN", "MPa"])),
            vec![0, 1, 0, 2]
        );
        assert_eq!(group_by_unit(&u(&["mm", "mm"])), vec![0, 0]);
        assert!(group_by_unit(&[]).is_empty());
    }
}
