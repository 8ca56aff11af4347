//! The traffic envelope figure: the extreme-fibre stresses along the girder of an
//! `[[influence]]` with `fibres = true` (envelopes_<name>.csv): the permanent state at the
//! stage the lines were taken, and the state plus the least and the largest traffic effect,
//! at the top and the bottom fibre (docs/theory-traffic.md).

use super::figures::{save, CurveFigure, Series};
use super::ViewError;
use std::path::{Path, PathBuf};

/// One fibre's envelope row: x [m], state, min, max [Pa].
type Row = (f64, f64, f64, f64);

/// The envelope figures of every envelopes_*.csv in `dir` that holds fibre rows, written to
/// `out` as `envelope_<name>`; the first traffic model of each file.
pub fn envelope_figures(dir: &Path, out: &Path) -> Result<Vec<PathBuf>, ViewError> {
    let mut files = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(files);
    };
    let mut csvs: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("envelopes_") && n.ends_with(".csv"))
        })
        .collect();
    csvs.sort();
    for path in csvs {
        let text = std::fs::read_to_string(&path)
            .map_err(|e| ViewError::Io(format!("{}: {e}", path.display())))?;
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .and_then(|s| s.strip_prefix("envelopes_"))
            .unwrap_or("")
            .to_string();
        if let Some(fig) = figure(&text, &name) {
            files.extend(save(&fig, out, &format!("envelope_{name}"))?);
        }
    }
    Ok(files)
}

/// The figure of one envelopes file's text, or None without fibre rows.
fn figure(text: &str, name: &str) -> Option<CurveFigure> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next()?.split(',').collect();
    let at = |key: &str| header.iter().position(|h| *h == key);
    let (monitor, traffic, state, min, max) = (
        at("monitor")?,
        at("traffic")?,
        at("state")?,
        at("min")?,
        at("max")?,
    );
    let mut first_traffic: Option<String> = None;
    let (mut top, mut bottom): (Vec<Row>, Vec<Row>) = (Vec::new(), Vec::new());
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let (Some(m), Some(t)) = (f.get(monitor), f.get(traffic)) else {
            continue;
        };
        if first_traffic.get_or_insert_with(|| t.to_string()) != t {
            continue;
        }
        let (list, x) = if let Some(x) = m.strip_prefix("sx top x=") {
            (&mut top, x)
        } else if let Some(x) = m.strip_prefix("sx bottom x=") {
            (&mut bottom, x)
        } else {
            continue;
        };
        let num = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok());
        if let (Ok(x), Some(s), Some(lo), Some(hi)) =
            (x.parse::<f64>(), num(state), num(min), num(max))
        {
            list.push((x, s, lo, hi));
        }
    }
    if top.is_empty() && bottom.is_empty() {
        return None;
    }
    let mut series = Vec::new();
    for (fibre, rows) in [("top", &mut top), ("bottom", &mut bottom)] {
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let curve = |label: &str, f: &dyn Fn(&Row) -> f64| Series {
            label: format!("{fibre}: {label}"),
            points: rows.iter().map(|r| (r.0, f(r) / 1e6)).collect(),
            panel: 0,
        };
        series.push(curve("permanent", &|r| r.1));
        series.push(curve("+ least traffic", &|r| r.1 + r.2));
        series.push(curve("+ largest traffic", &|r| r.1 + r.3));
    }
    Some(CurveFigure {
        title: format!(
            "Extreme-fibre stress along the girder, {} envelope ({name})",
            first_traffic.unwrap_or_default()
        ),
        x_label: "x [m]".into(),
        y_label: "σx, tension positive [MPa]".into(),
        y_labels: vec!["σx, tension positive [MPa]".into()],
        series,
        reference: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fibre rows become three curves per fibre, sorted along x, state + min and state + max
    /// in MPa; other monitors and other traffic models are left out.
    #[test]
    fn fibre_rows_become_sorted_envelope_curves() {
        let text = "monitor,unit,traffic,state,min,max\n\
            R_P1,N,LM1,1e6,-1e5,2e5\n\
            sx top x=2.0,Pa,LM1,-3e6,-1e6,5e5\n\
            sx top x=1.0,Pa,LM1,-2e6,-2e6,1e6\n\
            sx bottom x=1.0,Pa,LM1,1e6,-5e5,4e6\n\
            sx top x=1.0,Pa,HL93,9e9,9e9,9e9\n";
        let fig = figure(text, "deck").unwrap();
        assert_eq!(fig.series.len(), 6);
        let top_max = &fig.series[2];
        assert_eq!(top_max.label, "top: + largest traffic");
        assert_eq!(top_max.points, vec![(1.0, -1.0), (2.0, -2.5)]);
        let bottom_min = &fig.series[4];
        assert_eq!(bottom_min.points, vec![(1.0, 0.5)]);
        assert!(figure("monitor,unit,traffic,state,min,max\nR,N,LM1,1,2,3\n", "x").is_none());
    }
}
