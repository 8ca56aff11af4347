//! Readers for a finished run: `history.csv` (and reference CSVs of the same simple form),
//! `results.pvd`, and the `.vtu` files it lists, read back into plain arrays.
//!
//! The readers are tolerant: unknown data arrays are kept by name, line cells (VTK types 3
//! and 21, e.g. joints or tendons) are kept with the continuum cells, and `Float32`/`Int*`/
//! `UInt*` arrays in binary (UInt32 or UInt64 header) or ASCII format are accepted.

use super::ViewError;
use base64::Engine;
use std::path::{Path, PathBuf};

/// One column of a CSV table.
#[derive(Debug, Clone)]
pub struct Column {
    /// Header text as written, e.g. `midspan_uy [m]`.
    pub header: String,
    /// Name without the unit, e.g. `midspan_uy`.
    pub name: String,
    /// Unit between brackets, e.g. `m`; empty when the header has none.
    pub unit: String,
    /// Values, one per row (in the unit above).
    pub values: Vec<f64>,
}

impl Column {
    /// Axis label: `name [unit]`, or the name alone.
    pub fn label(&self) -> String {
        if self.unit.is_empty() {
            self.name.clone()
        } else {
            format!("{} [{}]", self.name, self.unit)
        }
    }
}

/// A CSV table with a header line: `history.csv` or a reference file.
#[derive(Debug, Clone)]
pub struct Table {
    /// File read.
    pub path: PathBuf,
    /// Columns, in file order.
    pub columns: Vec<Column>,
}

/// Split `name [unit]` into its parts.
fn split_header(h: &str) -> (String, String) {
    let h = h.trim();
    if let (Some(i), true) = (h.rfind('['), h.ends_with(']')) {
        let name = h[..i].trim().to_string();
        let unit = h[i + 1..h.len() - 1].trim().to_string();
        if !name.is_empty() {
            return (name, unit);
        }
    }
    (h.to_string(), String::new())
}

fn split_line(line: &str, delim: Option<char>) -> Vec<&str> {
    match delim {
        Some(d) => line.split(d).map(str::trim).collect(),
        None => line.split_whitespace().collect(),
    }
}

impl Table {
    /// Parse CSV text (comma, semicolon, tab or blank separated; lines starting with `#`
    /// and blank lines skipped; the first remaining line is the header).
    pub fn parse(text: &str, path: &Path) -> Result<Table, ViewError> {
        let p = path.display();
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let Some((_, header)) = lines.next() else {
            return Err(ViewError::Usage(format!(
                "{p}: empty file, expected a header line"
            )));
        };
        let delim = [',', ';', '\t'].into_iter().find(|d| header.contains(*d));
        let mut columns: Vec<Column> = split_line(header, delim)
            .into_iter()
            .map(|h| {
                let (name, unit) = split_header(h);
                Column {
                    header: h.to_string(),
                    name,
                    unit,
                    values: Vec::new(),
                }
            })
            .collect();
        for (i, line) in lines {
            let cells = split_line(line, delim);
            if cells.len() != columns.len() {
                return Err(ViewError::Usage(format!(
                    "{p}:{}: {} values, the header has {}",
                    i + 1,
                    cells.len(),
                    columns.len()
                )));
            }
            for (c, s) in columns.iter_mut().zip(cells) {
                let v: f64 = s.parse().map_err(|_| {
                    ViewError::Usage(format!("{p}:{}: '{s}' is not a number", i + 1))
                })?;
                c.values.push(v);
            }
        }
        Ok(Table {
            path: path.to_path_buf(),
            columns,
        })
    }

    /// Read and parse a CSV file.
    pub fn read(path: &Path) -> Result<Table, ViewError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ViewError::Usage(format!("{}: {e}", path.display())))?;
        Table::parse(&text, path)
    }

    /// Number of data rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }

    /// The column called `key`: matched against the name (monitor name, `step`,
    /// `factor:<case>`), then the full header, then the name ignoring case.
    pub fn column(&self, key: &str) -> Result<&Column, ViewError> {
        let key = key.trim();
        self.columns
            .iter()
            .find(|c| c.name == key)
            .or_else(|| self.columns.iter().find(|c| c.header.trim() == key))
            .or_else(|| {
                self.columns
                    .iter()
                    .find(|c| c.name.eq_ignore_ascii_case(key))
            })
            .ok_or_else(|| {
                ViewError::Usage(format!(
                    "{}: no column '{key}' (columns: {})",
                    self.path.display(),
                    self.columns
                        .iter()
                        .map(|c| c.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
    }

    /// Monitor columns of a history (after `step,increment,iterations` and `factor:*`).
    pub fn monitors(&self) -> impl Iterator<Item = &Column> {
        self.columns.iter().filter(|c| {
            !matches!(c.name.as_str(), "step" | "increment" | "iterations")
                && !c.name.starts_with("factor:")
        })
    }

    /// Load-factor columns of a history (`factor:<case>`).
    pub fn factors(&self) -> impl Iterator<Item = &Column> {
        self.columns
            .iter()
            .filter(|c| c.name.starts_with("factor:"))
    }
}

/// One entry of `results.pvd`.
#[derive(Debug, Clone)]
pub struct Output {
    /// `timestep` attribute (the history row number of the increment in segfem's files).
    pub time: f64,
    /// The `.vtu` file, resolved against the run directory.
    pub file: PathBuf,
    /// The line-cell piece of the same instant (part 1: joints and tendons), if any.
    pub lines: Option<PathBuf>,
    /// The joints' integration points of the same instant (part 4), if any.
    pub joint_points: Option<PathBuf>,
}

impl Output {
    /// The continuum grid with the joint line cells of the same instant appended (their
    /// `joint_opening` and `joint_normal_stress` arrays as `opening` and `normal_stress`;
    /// tendon spans left out), so that joint diagrams see them.
    pub fn grid(&self) -> Result<Grid, ViewError> {
        let mut g = Grid::read(&self.file)?;
        let Some(lines) = &self.lines else {
            return Ok(g);
        };
        let l = Grid::read(lines)?;
        let kind = l.cell_array("cell_kind").map(|a| a.values.clone());
        let keep: Vec<usize> = (0..l.cells.len())
            .filter(|&i| kind.as_ref().is_none_or(|k| k[i] == 1.0))
            .collect();
        if keep.is_empty() || l.points.len() != g.points.len() {
            return Ok(g);
        }
        let n0 = g.cells.len();
        for a in &mut g.cell_data {
            a.values
                .extend(std::iter::repeat_n(0.0, keep.len() * a.components));
        }
        for (src, dst) in [
            ("joint_opening", "opening"),
            ("joint_normal_stress", "normal_stress"),
        ] {
            if let Some(a) = l.cell_array(src) {
                let mut values = vec![0.0; n0 * a.components];
                for &i in &keep {
                    values.extend_from_slice(&a.values[i * a.components..(i + 1) * a.components]);
                }
                g.cell_data.push(Array {
                    name: dst.to_string(),
                    components: a.components,
                    values,
                });
            }
        }
        for &i in &keep {
            g.cells.push(l.cells[i].clone());
            g.types.push(l.types[i]);
        }
        Ok(g)
    }
}

impl Output {
    /// The tendon spans of this instant (line cells of part 1 with `cell_kind` 2, as the
    /// recorder writes them), each as its two end points (x, y) [m] at the undeformed
    /// position; empty without a line piece or a `cell_kind` array.
    pub fn tendon_spans(&self) -> Result<Vec<[[f64; 2]; 2]>, ViewError> {
        let Some(lines) = &self.lines else {
            return Ok(Vec::new());
        };
        let l = Grid::read(lines)?;
        let Some(kind) = l.cell_array("cell_kind") else {
            return Ok(Vec::new());
        };
        Ok((0..l.cells.len())
            .filter(|&i| kind.get(i, 0) == 2.0 && l.cells[i].len() >= 2)
            .map(|i| {
                let c = &l.cells[i];
                [l.points[c[0]], l.points[c[c.len() - 1]]]
            })
            .collect())
    }
}

/// Attributes of an XML start tag (`key="value"` pairs), in order.
fn attributes(tag: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = tag;
    while let Some(eq) = rest.find('=') {
        let key = rest[..eq]
            .split_whitespace()
            .last()
            .unwrap_or("")
            .to_string();
        let after = rest[eq + 1..].trim_start();
        let Some(q) = after.chars().next().filter(|c| *c == '"' || *c == '\'') else {
            break;
        };
        let body = &after[1..];
        let Some(end) = body.find(q) else { break };
        out.push((key, body[..end].to_string()));
        rest = &body[end + 1..];
    }
    out
}

fn attr<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// Read the `.pvd` collection in `dir` (`results.pvd`).
pub fn read_pvd(dir: &Path) -> Result<Vec<Output>, ViewError> {
    let path = dir.join("results.pvd");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        // A run whose every step has `output = "none"`, or run with --no-fields, writes no
        // field files.
        let why = if e.kind() == std::io::ErrorKind::NotFound && dir.join("summary.json").is_file()
        {
            " (the run wrote no field files: its steps have output = \"none\" or it ran with \
             --no-fields, or it stopped before its first field output)"
                .to_string()
        } else {
            String::new()
        };
        ViewError::Usage(format!("{}: {e}{why}", path.display()))
    })?;
    let mut out: Vec<Output> = Vec::new();
    let mut lines: Vec<(f64, PathBuf)> = Vec::new();
    let mut joint_points: Vec<(f64, PathBuf)> = Vec::new();
    for part in text.split("<DataSet").skip(1) {
        let tag = &part[..part.find('>').unwrap_or(part.len())];
        let a = attributes(tag);
        let Some(file) = attr(&a, "file") else {
            return Err(ViewError::Usage(format!(
                "{}: a DataSet without a file attribute",
                path.display()
            )));
        };
        let time = attr(&a, "timestep")
            .and_then(|t| t.parse().ok())
            .unwrap_or(out.len() as f64 + 1.0);
        // Part 0 is the continuum; part 1 the joints and tendons; part 2 the bars; part 3 the
        // concrete's Gauss points; part 4 the joints' integration points.
        match attr(&a, "part")
            .and_then(|p| p.parse::<usize>().ok())
            .unwrap_or(0)
        {
            0 => out.push(Output {
                time,
                file: dir.join(file),
                lines: None,
                joint_points: None,
            }),
            1 => lines.push((time, dir.join(file))),
            4 => joint_points.push((time, dir.join(file))),
            _ => {}
        }
    }
    for o in &mut out {
        o.lines = lines
            .iter()
            .find(|(t, _)| *t == o.time)
            .map(|(_, f)| f.clone());
        o.joint_points = joint_points
            .iter()
            .find(|(t, _)| *t == o.time)
            .map(|(_, f)| f.clone());
    }
    Ok(out)
}

/// A named data array of a grid: `values.len() == tuples × components`.
#[derive(Debug, Clone)]
pub struct Array {
    /// Array name (`stress`, `displacement`, `crack_angle`, ...).
    pub name: String,
    /// Components per tuple.
    pub components: usize,
    /// Flat values (SI units as written: m, Pa, ...).
    pub values: Vec<f64>,
}

impl Array {
    /// Component `c` of tuple `i`.
    pub fn get(&self, i: usize, c: usize) -> f64 {
        self.values[i * self.components + c]
    }
}

/// A `.vtu` piece read back: 2-D points, cells (VTK order), types and data arrays.
#[derive(Debug, Clone)]
pub struct Grid {
    /// File read.
    pub path: PathBuf,
    /// Point coordinates (x, y) [m]; z is dropped.
    pub points: Vec<[f64; 2]>,
    /// Cell connectivity (0-based point indices, VTK node order).
    pub cells: Vec<Vec<usize>>,
    /// VTK cell types (9/23/28 quadrilaterals, 5/22 triangles, 3/21 lines, ...).
    pub types: Vec<u8>,
    /// Point data arrays.
    pub point_data: Vec<Array>,
    /// Cell data arrays.
    pub cell_data: Vec<Array>,
}

impl Grid {
    /// Point array by name.
    pub fn point_array(&self, name: &str) -> Option<&Array> {
        self.point_data.iter().find(|a| a.name == name)
    }

    /// Cell array by name.
    pub fn cell_array(&self, name: &str) -> Option<&Array> {
        self.cell_data.iter().find(|a| a.name == name)
    }

    /// Whether cell `i` is a line cell (VTK 3 or 21).
    pub fn is_line(&self, i: usize) -> bool {
        matches!(self.types[i], 3 | 21)
    }

    /// Bounding box of the points: ([xmin, ymin], [xmax, ymax]) [m].
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        bounds(self.points.iter().copied())
    }

    /// Read a `.vtu` file.
    pub fn read(path: &Path) -> Result<Grid, ViewError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ViewError::Usage(format!("{}: {e}", path.display())))?;
        parse_vtu(&text, path)
    }
}

/// Bounding box of points.
pub fn bounds(pts: impl Iterator<Item = [f64; 2]>) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in pts {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !lo[0].is_finite() {
        return ([0.0; 2], [1.0; 2]);
    }
    (lo, hi)
}

/// A section (`<Points>`, `<Cells>`, ...) of the first piece: its inner text.
fn section<'a>(text: &'a str, name: &str) -> Option<&'a str> {
    let open = format!("<{name}");
    let start = text.find(&open)?;
    let after = &text[start + open.len()..];
    let gt = after.find('>')?;
    if after[..gt].ends_with('/') {
        return Some("");
    }
    let body = &after[gt + 1..];
    let end = body.find(&format!("</{name}>"))?;
    Some(&body[..end])
}

fn decode_array(
    tag_attrs: &[(String, String)],
    content: &str,
    header64: bool,
    path: &Path,
) -> Result<Array, ViewError> {
    let name = attr(tag_attrs, "Name").unwrap_or("").to_string();
    let bad = |m: String| ViewError::Usage(format!("{}: array '{name}': {m}", path.display()));
    let ty = attr(tag_attrs, "type").unwrap_or("Float64");
    let components: usize = attr(tag_attrs, "NumberOfComponents")
        .map(|s| {
            s.parse()
                .map_err(|_| bad(format!("bad component count '{s}'")))
        })
        .transpose()?
        .unwrap_or(1)
        .max(1);
    let format = attr(tag_attrs, "format").unwrap_or("ascii");
    let values: Vec<f64> = match format {
        "ascii" => content
            .split_whitespace()
            .map(|s| s.parse().map_err(|_| bad(format!("'{s}' is not a number"))))
            .collect::<Result<_, _>>()?,
        "binary" => {
            let clean: String = content.chars().filter(|c| !c.is_whitespace()).collect();
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(clean.as_bytes())
                .map_err(|e| bad(format!("bad base64: {e}")))?;
            let h = if header64 { 8 } else { 4 };
            if bytes.len() < h {
                return Err(bad("truncated binary block".into()));
            }
            let n = if header64 {
                u64::from_le_bytes(bytes[..8].try_into().expect("8 bytes")) as usize
            } else {
                u32::from_le_bytes(bytes[..4].try_into().expect("4 bytes")) as usize
            };
            let data = bytes
                .get(h..h + n)
                .ok_or_else(|| bad(format!("byte count {n} exceeds the data")))?;
            let size = match ty {
                "Float64" | "Int64" | "UInt64" => 8,
                "Float32" | "Int32" | "UInt32" => 4,
                "Int16" | "UInt16" => 2,
                "Int8" | "UInt8" => 1,
                o => return Err(bad(format!("unsupported type '{o}'"))),
            };
            data.chunks_exact(size)
                .map(|c| match ty {
                    "Float64" => f64::from_le_bytes(c.try_into().expect("8")),
                    "Int64" => i64::from_le_bytes(c.try_into().expect("8")) as f64,
                    "UInt64" => u64::from_le_bytes(c.try_into().expect("8")) as f64,
                    "Float32" => f32::from_le_bytes(c.try_into().expect("4")) as f64,
                    "Int32" => i32::from_le_bytes(c.try_into().expect("4")) as f64,
                    "UInt32" => u32::from_le_bytes(c.try_into().expect("4")) as f64,
                    "Int16" => i16::from_le_bytes(c.try_into().expect("2")) as f64,
                    "UInt16" => u16::from_le_bytes(c.try_into().expect("2")) as f64,
                    "Int8" => c[0] as i8 as f64,
                    _ => c[0] as f64,
                })
                .collect()
        }
        o => {
            return Err(bad(format!(
                "format '{o}' is not supported (ascii, binary)"
            )))
        }
    };
    if values.len() % components != 0 {
        return Err(bad(format!(
            "{} values are not a whole number of {components}-component tuples",
            values.len()
        )));
    }
    Ok(Array {
        name,
        components,
        values,
    })
}

/// All `<DataArray>` elements of a section.
fn arrays(sec: &str, header64: bool, path: &Path) -> Result<Vec<Array>, ViewError> {
    let mut out = Vec::new();
    let mut rest = sec;
    while let Some(s) = rest.find("<DataArray") {
        let after = &rest[s + "<DataArray".len()..];
        let gt = after.find('>').ok_or_else(|| {
            ViewError::Usage(format!("{}: unterminated DataArray tag", path.display()))
        })?;
        let tag = &after[..gt];
        let a = attributes(tag);
        if tag.ends_with('/') {
            out.push(decode_array(&a, "", header64, path)?);
            rest = &after[gt + 1..];
            continue;
        }
        let body = &after[gt + 1..];
        let end = body.find("</DataArray>").ok_or_else(|| {
            ViewError::Usage(format!("{}: unterminated DataArray", path.display()))
        })?;
        out.push(decode_array(&a, &body[..end], header64, path)?);
        rest = &body[end..];
    }
    Ok(out)
}

/// Parse the text of a `.vtu` file (first piece only).
pub fn parse_vtu(text: &str, path: &Path) -> Result<Grid, ViewError> {
    let bad = |m: &str| ViewError::Usage(format!("{}: {m}", path.display()));
    let head = text
        .find("<VTKFile")
        .map(|i| &text[i..i + text[i..].find('>').unwrap_or(0)])
        .ok_or_else(|| bad("not a VTK XML file"))?;
    let ha = attributes(head);
    if attr(&ha, "type") != Some("UnstructuredGrid") {
        return Err(bad("not a VTK UnstructuredGrid file"));
    }
    if attr(&ha, "compressor").is_some() {
        return Err(bad("compressed VTK files are not supported"));
    }
    if text.contains("<AppendedData") {
        return Err(bad("appended VTK data is not supported"));
    }
    // A file cut short (a copy interrupted, a disk full) can still hold the points and
    // cells with the data arrays missing: refused rather than read as a grid without data.
    if !text.trim_end().ends_with("</VTKFile>") {
        return Err(bad(
            "truncated: the file does not end with </VTKFile> (cut short while written or copied?)",
        ));
    }
    let header64 = attr(&ha, "header_type") == Some("UInt64");
    let piece_tag = text
        .find("<Piece")
        .map(|i| &text[i..i + text[i..].find('>').unwrap_or(0)])
        .ok_or_else(|| bad("no Piece"))?;
    let pa = attributes(piece_tag);
    let n_points: usize = attr(&pa, "NumberOfPoints")
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| bad("Piece without NumberOfPoints"))?;
    let n_cells: usize = attr(&pa, "NumberOfCells")
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| bad("Piece without NumberOfCells"))?;
    let pts = arrays(section(text, "Points").unwrap_or(""), header64, path)?;
    let pts = pts.first().ok_or_else(|| bad("no point coordinates"))?;
    if pts.values.len() != n_points * pts.components || pts.components < 2 {
        return Err(bad("point coordinates do not match NumberOfPoints"));
    }
    let points: Vec<[f64; 2]> = (0..n_points)
        .map(|i| [pts.get(i, 0), pts.get(i, 1)])
        .collect();
    let cell_arrays = arrays(section(text, "Cells").unwrap_or(""), header64, path)?;
    let find = |n: &str| {
        cell_arrays
            .iter()
            .find(|a| a.name == n)
            .ok_or_else(|| bad(&format!("no '{n}' cell array")))
    };
    let conn = find("connectivity")?;
    let offsets = find("offsets")?;
    let types = find("types")?;
    if offsets.values.len() != n_cells || types.values.len() != n_cells {
        return Err(bad("cell arrays do not match NumberOfCells"));
    }
    let mut cells = Vec::with_capacity(n_cells);
    let mut start = 0usize;
    for &o in &offsets.values {
        let end = o as usize;
        if end < start || end > conn.values.len() {
            return Err(bad("cell offsets out of order"));
        }
        let c: Vec<usize> = conn.values[start..end]
            .iter()
            .map(|&v| v as usize)
            .collect();
        if c.iter().any(|&n| n >= n_points) {
            return Err(bad("cell connectivity refers to a missing point"));
        }
        cells.push(c);
        start = end;
    }
    let types: Vec<u8> = types.values.iter().map(|&t| t as u8).collect();
    let check = |list: Vec<Array>, n: usize, what: &str| -> Result<Vec<Array>, ViewError> {
        for a in &list {
            if a.values.len() != n * a.components {
                return Err(bad(&format!(
                    "{what} array '{}' has {} values for {n} tuples",
                    a.name,
                    a.values.len()
                )));
            }
        }
        Ok(list)
    };
    let point_data = check(
        arrays(section(text, "PointData").unwrap_or(""), header64, path)?,
        n_points,
        "point",
    )?;
    let cell_data = check(
        arrays(section(text, "CellData").unwrap_or(""), header64, path)?,
        n_cells,
        "cell",
    )?;
    Ok(Grid {
        path: path.to_path_buf(),
        points,
        cells,
        types,
        point_data,
        cell_data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_units_split() {
        assert_eq!(
            split_header("midspan_uy [m]"),
            ("midspan_uy".into(), "m".into())
        );
        assert_eq!(
            split_header("factor:Q [-]"),
            ("factor:Q".into(), "-".into())
        );
        assert_eq!(split_header("P"), ("P".into(), String::new()));
    }

    #[test]
    fn csv_columns_by_name() {
        let t = Table::parse("# ref\nu [mm]; P [kN]\n1;2\n3;4\n", Path::new("r.csv")).unwrap();
        assert_eq!(t.rows(), 2);
        assert_eq!(t.column("P").unwrap().values, vec![2.0, 4.0]);
        assert_eq!(t.column("u [mm]").unwrap().unit, "mm");
        assert!(t.column("v").is_err());
        assert!(Table::parse("a,b\n1\n", Path::new("r.csv")).is_err());
    }

    #[test]
    fn vtu_round_trip_with_line_cells_and_extra_arrays() {
        use crate::results::vtu::{render, Array as A, Grid as G};
        let points = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let cells = vec![vec![0, 1, 2, 3], vec![1, 2]];
        let doc = render(
            &G {
                points: &points,
                cells: &cells,
                types: &[9, 3],
            },
            &[A::F64 {
                name: "displacement",
                components: 3,
                values: &[0.0; 12],
            }],
            &[
                A::I32 {
                    name: "region",
                    values: &[0, 1],
                },
                A::F64 {
                    name: "opening",
                    components: 1,
                    values: &[0.5, 1.5],
                },
            ],
        );
        let g = parse_vtu(&doc, Path::new("t.vtu")).unwrap();
        assert_eq!(g.points, points.to_vec());
        assert_eq!(g.cells, cells);
        assert_eq!(g.types, vec![9, 3]);
        assert!(g.is_line(1));
        assert_eq!(g.cell_array("opening").unwrap().values, vec![0.5, 1.5]);
        assert_eq!(g.point_array("displacement").unwrap().components, 3);
        // Cut anywhere after the cells (the data arrays lost), the file is refused.
        let cells_end = doc.find("</Cells>").unwrap() + "</Cells>".len();
        for cut in [cells_end, cells_end + 10, doc.len() - 12] {
            let e = parse_vtu(&doc[..cut], Path::new("t.vtu")).unwrap_err();
            assert!(e.to_string().contains("truncated"), "{e}");
        }
    }
}
