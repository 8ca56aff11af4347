//! End-to-end tests through the built `segfem` binary: bundled examples, `check`, `run` and
//! every output file (history.csv, summary.json, results.pvd and the .vtu files it lists),
//! checked against numbers that a wrong program would not produce.

mod common;

use common::{code, segfem, stderr, stdout, TempDir};
use std::collections::HashMap;
use std::path::Path;

// ---------------------------------------------------------------------------------------
// Small parsers (std only).
// ---------------------------------------------------------------------------------------

/// Standard base64 (RFC 4648, with padding) decoded by hand.
fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    fn val(c: u8) -> Result<u32, String> {
        Ok(match c {
            b'A'..=b'Z' => (c - b'A') as u32,
            b'a'..=b'z' => (c - b'a') as u32 + 26,
            b'0'..=b'9' => (c - b'0') as u32 + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return Err(format!("invalid base64 character {:?}", c as char)),
        })
    }
    let bytes: Vec<u8> = s.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
    if bytes.len() % 4 != 0 {
        return Err(format!(
            "base64 length {} is not a multiple of 4",
            bytes.len()
        ));
    }
    let mut out = Vec::with_capacity(bytes.len() / 4 * 3);
    for (i, q) in bytes.chunks(4).enumerate() {
        let last = i == bytes.len() / 4 - 1;
        let pad = q.iter().rev().take_while(|&&c| c == b'=').count();
        if pad > 2 || (pad > 0 && !last) {
            return Err("misplaced base64 padding".into());
        }
        let mut n = 0u32;
        for &c in &q[..4 - pad] {
            n = (n << 6) | val(c)?;
        }
        n <<= 6 * pad as u32;
        let b = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&b[..3 - pad]);
    }
    Ok(out)
}

/// One XML element as seen by the simple checker: name, attributes and the text directly
/// inside it (only kept for leaf elements, which is all the .vtu arrays need).
#[derive(Debug, Clone)]
struct XmlElement {
    name: String,
    attrs: HashMap<String, String>,
    text: String,
}

/// Parse `key="value"` pairs of a start tag.
fn parse_attrs(s: &str) -> Result<HashMap<String, String>, String> {
    let mut attrs = HashMap::new();
    let mut rest = s.trim();
    while !rest.is_empty() {
        let eq = rest
            .find('=')
            .ok_or_else(|| format!("attribute without '=' in {s:?}"))?;
        let key = rest[..eq].trim().to_string();
        let after = rest[eq + 1..].trim_start();
        let quote = after
            .chars()
            .next()
            .filter(|c| *c == '"' || *c == '\'')
            .ok_or_else(|| format!("unquoted attribute value in {s:?}"))?;
        let end = after[1..]
            .find(quote)
            .ok_or_else(|| format!("unterminated attribute value in {s:?}"))?;
        if key.is_empty()
            || attrs
                .insert(key.clone(), after[1..1 + end].to_string())
                .is_some()
        {
            return Err(format!("empty or repeated attribute {key:?} in {s:?}"));
        }
        rest = after[end + 2..].trim_start();
    }
    Ok(attrs)
}

/// A tiny well-formedness check: one root element, every start tag closed by a matching end
/// tag in the right order, no stray '<' in text. Returns all elements in document order.
fn parse_xml(doc: &str) -> Result<Vec<XmlElement>, String> {
    let mut stack: Vec<usize> = Vec::new(); // indices into `elements`
    let mut elements: Vec<XmlElement> = Vec::new();
    let mut roots = 0;
    let mut rest = doc;
    while let Some(lt) = rest.find('<') {
        let text = &rest[..lt];
        match stack.last() {
            Some(&top) => elements[top].text.push_str(text),
            None if !text.trim().is_empty() => {
                return Err(format!("text outside the root element: {text:?}"))
            }
            None => {}
        }
        rest = &rest[lt..];
        if let Some(r) = rest.strip_prefix("<?") {
            let end = r.find("?>").ok_or("unterminated <? ?>")?;
            if roots > 0 || !stack.is_empty() {
                return Err("processing instruction after the root element started".into());
            }
            rest = &r[end + 2..];
            continue;
        }
        if let Some(r) = rest.strip_prefix("<!--") {
            let end = r.find("-->").ok_or("unterminated comment")?;
            rest = &r[end + 3..];
            continue;
        }
        let gt = rest.find('>').ok_or("unterminated tag")?;
        let tag = &rest[1..gt];
        rest = &rest[gt + 1..];
        if tag.contains('<') {
            return Err(format!("'<' inside tag {tag:?}"));
        }
        if let Some(name) = tag.strip_prefix('/') {
            let top = stack
                .pop()
                .ok_or_else(|| format!("end tag </{name}> with nothing open"))?;
            if elements[top].name != name.trim() {
                return Err(format!(
                    "end tag </{}> closes <{}>",
                    name.trim(),
                    elements[top].name
                ));
            }
            continue;
        }
        let (body, self_closing) = match tag.strip_suffix('/') {
            Some(b) => (b, true),
            None => (tag, false),
        };
        let name_end = body.find(|c: char| c.is_whitespace()).unwrap_or(body.len());
        let name = &body[..name_end];
        if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
            return Err(format!("bad element name in <{tag}>"));
        }
        if stack.is_empty() {
            roots += 1;
            if roots > 1 {
                return Err("more than one root element".into());
            }
        }
        elements.push(XmlElement {
            name: name.to_string(),
            attrs: parse_attrs(&body[name_end..])?,
            text: String::new(),
        });
        if !self_closing {
            stack.push(elements.len() - 1);
        }
    }
    if !rest.trim().is_empty() {
        return Err(format!("text after the root element: {rest:?}"));
    }
    if let Some(&top) = stack.last() {
        return Err(format!("<{}> is never closed", elements[top].name));
    }
    if roots != 1 {
        return Err("no root element".into());
    }
    Ok(elements)
}

/// history.csv: the header names and the rows as numbers.
struct History {
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl History {
    fn parse(text: &str) -> Self {
        let mut lines = text.lines();
        let header: Vec<String> = lines
            .next()
            .expect("history.csv has a header")
            .split(',')
            .map(str::to_string)
            .collect();
        let rows: Vec<Vec<f64>> = lines
            .map(|l| {
                let r: Vec<f64> = l
                    .split(',')
                    .map(|v| v.parse().unwrap_or_else(|_| panic!("not a number: {v:?}")))
                    .collect();
                assert_eq!(r.len(), header.len(), "row length != header length: {l}");
                r
            })
            .collect();
        Self { header, rows }
    }

    /// Column index whose header starts with `name` followed by " [".
    fn col(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| h.starts_with(&format!("{name} [")))
            .unwrap_or_else(|| panic!("no column {name:?} in {:?}", self.header))
    }

    fn column(&self, name: &str) -> Vec<f64> {
        let c = self.col(name);
        self.rows.iter().map(|r| r[c]).collect()
    }
}

/// Steps of a model file, read by hand: (increments, output every increment).
fn steps_of(model_text: &str) -> Vec<(usize, bool)> {
    let mut steps = Vec::new();
    let mut in_step = false;
    for raw in model_text.lines() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.starts_with('[') {
            in_step = line == "[[steps]]";
            if in_step {
                steps.push((1, false));
            }
            continue;
        }
        if !in_step {
            continue;
        }
        if let Some((k, v)) = line.split_once('=') {
            let last = steps.last_mut().expect("inside a step");
            match k.trim() {
                "increments" => last.0 = v.trim().parse().expect("increments is an integer"),
                "output" => last.1 = v.trim() == "\"increments\"",
                _ => {}
            }
        }
    }
    steps
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Relative difference, for comparisons against closed-form values.
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

// ---------------------------------------------------------------------------------------
// Box-beam data (examples/box-beam.toml).
// ---------------------------------------------------------------------------------------

const RHO: f64 = 2548.4; // kg/m³
const G: f64 = 9.81; // m/s²
const SPAN: f64 = 7.2; // m
const E_MOD: f64 = 35.5e9; // Pa
/// Band depths [m] and thicknesses [m], bottom up.
const BANDS: [(f64, f64); 3] = [(0.10, 0.70), (0.40, 0.20), (0.10, 1.20)];
/// Area of the section [m²]: 0.7·0.1 + 0.2·0.4 + 1.2·0.1.
const AREA: f64 = 0.7 * 0.1 + 0.2 * 0.4 + 1.2 * 0.1;
/// Elements along and through the beam: nx = 72, rows 2 + 6 + 2.
const NX: usize = 72;
const NY: usize = 10;

/// Second moment of area of the section about its centroid [m⁴].
fn box_inertia() -> f64 {
    let (mut a, mut s, mut i0, mut y) = (0.0, 0.0, 0.0, 0.0);
    for (d, t) in BANDS {
        let ab = d * t;
        let yc = y + d / 2.0;
        a += ab;
        s += ab * yc;
        i0 += t * d * d * d / 12.0 + ab * yc * yc;
        y += d;
    }
    i0 - s * s / a
}

/// Writes box-beam.toml with `segfem example` and runs it into `out`.
fn run_box_beam(tmp: &TempDir) -> (String, std::process::Output) {
    let o = segfem(tmp.path(), &["example", "box-beam", "-o", "f.toml"]);
    assert_eq!(code(&o), 0, "example failed: {}", stderr(&o));
    let text = read(&tmp.join("f.toml"));
    let o = segfem(tmp.path(), &["run", "f.toml", "-o", "out"]);
    assert_eq!(code(&o), 0, "run failed: {}", stderr(&o));
    (text, o)
}

// ---------------------------------------------------------------------------------------
// Tests.
// ---------------------------------------------------------------------------------------

#[test]
fn base64_decoder_known_values() {
    // RFC 4648 §10 test vectors: the decoder is itself tested before it tests the program.
    for (enc, dec) in [
        ("", ""),
        ("Zg==", "f"),
        ("Zm8=", "fo"),
        ("Zm9v", "foo"),
        ("Zm9vYg==", "foob"),
        ("Zm9vYmE=", "fooba"),
        ("Zm9vYmFy", "foobar"),
    ] {
        assert_eq!(base64_decode(enc).unwrap(), dec.as_bytes());
    }
    assert!(base64_decode("Zm9").is_err());
    assert!(base64_decode("Zm=v").is_err());
}

#[test]
fn xml_checker_rejects_unbalanced() {
    assert!(parse_xml("<?xml version=\"1.0\"?>\n<a><b x=\"1\"/><c>t</c></a>\n").is_ok());
    assert!(parse_xml("<a><b></a></b>").is_err());
    assert!(parse_xml("<a><b></b>").is_err());
    assert!(parse_xml("<a></a><a></a>").is_err());
    assert!(parse_xml("<a x=1></a>").is_err());
    assert!(parse_xml("<a></a>junk").is_err());
}

#[test]
fn example_lists_bundled_examples_and_writes_them() {
    let tmp = TempDir::new("example");
    let o = segfem(tmp.path(), &["example"]);
    assert_eq!(code(&o), 0);
    let list = stdout(&o);
    let names: Vec<&str> = list
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(names.contains(&"box-beam"), "{list}");
    assert!(names.contains(&"cantilever"), "{list}");
    // The descriptions start in one column (after the longest name and two spaces).
    let starts: Vec<usize> = list
        .lines()
        .map(|l| {
            let name = l.split_whitespace().next().unwrap();
            name.len() + l[name.len()..].len() - l[name.len()..].trim_start().len()
        })
        .collect();
    let longest = names.iter().map(|n| n.len()).max().unwrap();
    assert!(starts.iter().all(|&s| s == longest + 2), "{list}");
    // Every listed example is written verbatim (to stdout and to a file), and is the file
    // shipped in examples/.
    for name in &names {
        let shipped =
            read(&Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/{name}.toml")));
        let o = segfem(tmp.path(), &["example", name]);
        assert_eq!(code(&o), 0);
        assert_eq!(stdout(&o), shipped, "example {name} on stdout");
        let file = format!("{name}.toml");
        let o = segfem(tmp.path(), &["example", name, "-o", &file]);
        assert_eq!(code(&o), 0);
        assert_eq!(read(&tmp.join(&file)), shipped, "example {name} -o");
        // Each one is a valid model.
        let o = segfem(tmp.path(), &["check", &file]);
        assert_eq!(code(&o), 0, "{name}: {}", stderr(&o));
    }
    // An unknown name is an input error that lists the available ones.
    let o = segfem(tmp.path(), &["example", "no-such-beam"]);
    assert_eq!(code(&o), 2);
    let err = stderr(&o);
    assert!(
        err.starts_with("error: ") && err.contains("no-such-beam"),
        "{err}"
    );
    assert!(
        err.contains("box-beam") && err.contains("cantilever"),
        "{err}"
    );
}

#[test]
fn check_prints_the_summary() {
    let tmp = TempDir::new("check");
    assert_eq!(
        code(&segfem(
            tmp.path(),
            &["example", "box-beam", "-o", "f.toml"]
        )),
        0
    );
    let o = segfem(tmp.path(), &["check", "f.toml"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert_eq!(stderr(&o), "", "a valid example gives no warnings");
    let out = stdout(&o);
    let field = |k: &str| -> String {
        out.lines()
            .find_map(|l| l.trim().strip_prefix(&format!("{k}:")))
            .unwrap_or_else(|| panic!("no '{k}:' line in\n{out}"))
            .trim()
            .to_string()
    };
    assert!(out.starts_with("f.toml: valid"), "{out}");
    // Q8 banded mesh: (2nx+1)(2ny+1) grid points less one centre point per element.
    let nodes = (2 * NX + 1) * (2 * NY + 1) - NX * NY;
    assert_eq!(field("nodes"), nodes.to_string());
    assert_eq!(field("elements"), (NX * NY).to_string());
    assert_eq!(field("dofs"), (2 * nodes).to_string());
    assert_eq!(field("title"), "Box-section beam, 7.2 m span, elastic");
    assert!(field("regions").contains("webs (t = 0.2 m)"), "{out}");
    // left holds ux and uy at one node, right uy at one node.
    assert_eq!(field("supports"), "left (2 dofs), right (1 dof)");
    // Free equations: every dof but the three held (left x and y, right y).
    assert_eq!(
        field("equations").split(' ').next(),
        Some((2 * nodes - 3).to_string()).as_deref()
    );
    assert_eq!(field("joints"), "none");
    assert_eq!(field("loads"), "self_weight, Q");
    assert_eq!(field("monitors"), "midspan_uy, R_left, Q");
    assert_eq!(field("steps"), "self_weight, service");
    // check writes nothing.
    assert_eq!(tmp.entries(), vec!["f.toml".to_string()]);
}

#[test]
fn closed_stdout_pipe_ends_quietly() {
    // `segfem check m.toml | head -1`: the reader goes away before segfem writes. The read
    // end is dropped right after spawning, long before the process has parsed the model,
    // so its first write meets a closed pipe; `println!` would panic there (status 101).
    let tmp = TempDir::new("pipe");
    assert_eq!(
        code(&segfem(
            tmp.path(),
            &["example", "box-beam", "-o", "f.toml"]
        )),
        0
    );
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_segfem"))
        .args(["check", "f.toml"])
        .current_dir(tmp.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spawn segfem");
    drop(child.stdout.take());
    let o = child.wait_with_output().expect("wait for segfem");
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
}

#[test]
fn box_beam_history_is_physically_right() {
    let tmp = TempDir::new("history");
    let (model_text, o) = run_box_beam(&tmp);
    let h = History::parse(&read(&tmp.join("out/history.csv")));
    // Header: three counters, then every column carries a unit in brackets.
    assert_eq!(h.header[..3], ["step", "increment", "iterations"]);
    for c in &h.header[3..] {
        let unit = c.rsplit_once(" [").map(|(_, u)| u);
        assert!(
            matches!(unit, Some(u) if u.ends_with(']') && u.len() > 1),
            "column {c:?} has no unit"
        );
    }
    assert_eq!(h.header[h.col("midspan_uy")], "midspan_uy [m]");
    assert_eq!(h.header[h.col("R_left")], "R_left [N]");
    assert_eq!(h.header[h.col("factor:Q")], "factor:Q [-]");
    // One row per converged increment: the total increments of the steps in the file.
    let steps = steps_of(&model_text);
    assert_eq!(
        steps,
        vec![(1, false), (4, true)],
        "steps read from the file"
    );
    let total: usize = steps.iter().map(|s| s.0).sum();
    assert_eq!(h.rows.len(), total);
    // Step and increment counters run 1.., increment by increment.
    let expect: Vec<(f64, f64)> = steps
        .iter()
        .enumerate()
        .flat_map(|(s, &(n, _))| (1..=n).map(move |i| ((s + 1) as f64, i as f64)))
        .collect();
    let got: Vec<(f64, f64)> = h.rows.iter().map(|r| (r[0], r[1])).collect();
    assert_eq!(got, expect);
    // Elastic: every increment converges in one Newton iteration (a linear problem).
    assert!(
        h.rows.iter().all(|r| r[2] == 1.0),
        "iterations {:?}",
        h.rows
    );

    let sw = h.column("factor:self_weight");
    let q = h.column("factor:Q");
    let r_left = h.column("R_left");
    let uy = h.column("midspan_uy");
    // Factors: totals at the end of each step, reached linearly from the previous step's:
    // self weight 1 throughout, Q = 56·k/4 in the four increments of the second step.
    // (Exact: k/4 and 56·k/4 are exact in binary floating point for these k.)
    assert_eq!(sw, vec![1.0; 5]);
    assert_eq!(q, vec![0.0, 14.0, 28.0, 42.0, 56.0]);
    assert_eq!(
        h.column("Q"),
        q,
        "load_factor monitor equals the factor column"
    );

    // Self weight alone: the left reaction is half the weight ρ g A L (symmetric load and
    // supports). 1e-6 relative: the consistent body load integrates ρ g t over the exact
    // rectangle areas, and equilibrium holds to the solver's residual (~1e-12), so only
    // round-off separates the two.
    let weight = RHO * G * AREA * SPAN;
    assert!(
        rel(r_left[0], weight / 2.0) < 1e-6,
        "R_left = {} N, expected W/2 = {} N",
        r_left[0],
        weight / 2.0
    );
    // With the two point loads of 1 kN × Q at the third points (symmetric), the left
    // reaction grows by 1 kN per unit of Q. Same tolerance, same reason.
    for (r, qk) in r_left.iter().zip(&q) {
        let expected = weight / 2.0 + 1.0e3 * qk;
        assert!(rel(*r, expected) < 1e-6, "R_left {r} vs {expected}");
    }

    // Midspan deflection under self weight against beam theory: 5 w L⁴ / (384 E I) is a
    // lower bound (it leaves out shear deformation, which only adds deflection); shear and
    // the local effects of point supports add a few per cent for L/h = 12, so the FE value
    // must lie between 1.0 and 1.12 times the bending value. A wrong stiffness, thickness
    // or sign fails this.
    let i = box_inertia();
    let w = RHO * G * AREA;
    let bending = 5.0 * w * SPAN.powi(4) / (384.0 * E_MOD * i);
    let ratio = -uy[0] / bending;
    assert!(
        (1.0..1.12).contains(&ratio),
        "midspan uy = {} m, bending theory {} m (ratio {ratio})",
        uy[0],
        -bending
    );
    // Loads at the third points a = L/3: P a (3L² − 4a²) / (24 E I) per unit of Q; the
    // deflection added by Q (elastic, so superposition holds) against it, same bounds.
    let a = SPAN / 3.0;
    let per_q = 1.0e3 * a * (3.0 * SPAN * SPAN - 4.0 * a * a) / (24.0 * E_MOD * i);
    let added = uy[0] - uy[4];
    let ratio_q = added / (56.0 * per_q);
    assert!(
        (1.0..1.12).contains(&ratio_q),
        "Q deflection ratio {ratio_q}"
    );
    // Linear elastic: equal load increments give equal deflection increments (1e-9
    // relative: the solves differ only by round-off, ~1e-12 of the residual tolerance).
    let d: Vec<f64> = uy.windows(2).skip(1).map(|p| p[1] - p[0]).collect();
    for x in &d {
        assert!(rel(*x, d[0]) < 1e-9, "deflection steps {d:?}");
    }
    // The command line prints the final monitors and where the results are.
    let out = stdout(&o);
    assert!(out.contains("5 increments"), "{out}");
    assert!(out.contains("R_left = "), "{out}");
    assert!(out.contains("results in out"), "{out}");
}

#[test]
fn box_beam_summary_matches_the_mesh() {
    let tmp = TempDir::new("summary");
    let (_, _) = run_box_beam(&tmp);
    let s: serde_json::Value =
        serde_json::from_str(&read(&tmp.join("out/summary.json"))).expect("summary.json is JSON");
    assert_eq!(s["status"], "completed");
    assert!(s["error"].is_null());
    assert_eq!(s["title"], "Box-section beam, 7.2 m span, elastic");
    let nodes = (2 * NX + 1) * (2 * NY + 1) - NX * NY;
    let size = &s["size"];
    assert_eq!(size["nodes"], nodes);
    assert_eq!(size["elements"], NX * NY);
    assert_eq!(size["dofs"], 2 * nodes);
    // Two supports restrain three dofs (left ux, uy; right uy).
    assert_eq!(size["equations"], 2 * nodes - 3);
    let t = &s["timings"];
    assert_eq!(t["increments"], 5);
    assert_eq!(t["iterations"], 5);
    // Elastic: one factorisation serves every increment.
    assert_eq!(t["solver"]["factorisations"], 1);
    assert!(s["wall_s"].as_f64().unwrap() > 0.0);
    // Final monitors equal the last history row.
    let h = History::parse(&read(&tmp.join("out/history.csv")));
    let last = h.rows.last().unwrap();
    let fm = s["final_monitors"].as_array().unwrap();
    let names: Vec<&str> = fm.iter().map(|p| p[0].as_str().unwrap()).collect();
    assert_eq!(names, ["midspan_uy", "R_left", "Q"]);
    for p in fm {
        let name = p[0].as_str().unwrap();
        // Both come from the same f64; the CSV prints it with `{:e}` (shortest round trip).
        assert_eq!(p[1].as_f64().unwrap(), last[h.col(name)], "{name}");
    }
    assert_eq!(s["warnings"].as_array().unwrap().len(), 0);
}

#[test]
fn box_beam_vtu_files_are_complete() {
    let tmp = TempDir::new("vtu");
    let (model_text, _) = run_box_beam(&tmp);
    let out = tmp.join("out");
    let s: serde_json::Value = serde_json::from_str(&read(&out.join("summary.json"))).unwrap();
    let n_points = s["size"]["nodes"].as_u64().unwrap() as usize;
    let n_cells = s["size"]["elements"].as_u64().unwrap() as usize;

    let pvd = parse_xml(&read(&out.join("results.pvd"))).expect("results.pvd well-formed");
    assert_eq!(pvd[0].name, "VTKFile");
    assert_eq!(pvd[0].attrs["type"], "Collection");
    let files: Vec<String> = pvd
        .iter()
        .filter(|e| e.name == "DataSet")
        .map(|e| e.attrs["file"].clone())
        .collect();
    // Field output: one file at the end of a step, or one per increment with
    // output = "increments".
    let expected: usize = steps_of(&model_text)
        .iter()
        .map(|&(n, every)| if every { n } else { 1 })
        .sum();
    assert_eq!(files.len(), expected, "{files:?}");
    let times: Vec<f64> = pvd
        .iter()
        .filter(|e| e.name == "DataSet")
        .map(|e| e.attrs["timestep"].parse().unwrap())
        .collect();
    assert!(
        times.windows(2).all(|w| w[0] < w[1]),
        "timesteps increase: {times:?}"
    );
    // Nothing but the listed files, history, summary and checkpoint in the directory (no
    // temporaries).
    let mut want: Vec<String> = files.clone();
    want.extend(
        [
            "checkpoint.bin",
            "history.csv",
            "results.pvd",
            "summary.json",
        ]
        .map(String::from),
    );
    want.sort();
    let mut have: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    have.sort();
    assert_eq!(have, want);

    let h = History::parse(&read(&out.join("history.csv")));
    let weight = RHO * G * AREA * SPAN;
    for (k, f) in files.iter().enumerate() {
        let doc = read(&out.join(f));
        let els = parse_xml(&doc).unwrap_or_else(|e| panic!("{f}: not well-formed: {e}"));
        assert_eq!(els[0].name, "VTKFile");
        assert_eq!(els[0].attrs["byte_order"], "LittleEndian");
        assert_eq!(els[0].attrs["header_type"], "UInt32");
        let piece = els.iter().find(|e| e.name == "Piece").expect("a Piece");
        assert_eq!(piece.attrs["NumberOfPoints"], n_points.to_string(), "{f}");
        assert_eq!(piece.attrs["NumberOfCells"], n_cells.to_string(), "{f}");
        // Which section each DataArray is in decides its tuple count.
        let mut section = String::new();
        let mut arrays: HashMap<String, Vec<u8>> = HashMap::new();
        let mut n_arrays = 0;
        for e in &els {
            match e.name.as_str() {
                "Points" | "Cells" | "PointData" | "CellData" => section = e.name.clone(),
                "DataArray" => {
                    n_arrays += 1;
                    let name = &e.attrs["Name"];
                    assert_eq!(e.attrs["format"], "binary", "{f}: {name}");
                    let raw = base64_decode(e.text.trim())
                        .unwrap_or_else(|err| panic!("{f}: {name}: {err}"));
                    assert!(raw.len() >= 4, "{f}: {name}: no header");
                    let count = u32::from_le_bytes(raw[..4].try_into().unwrap()) as usize;
                    let data = raw[4..].to_vec();
                    assert_eq!(count, data.len(), "{f}: {name}: header vs data length");
                    let comps: usize = e
                        .attrs
                        .get("NumberOfComponents")
                        .map(|c| c.parse().unwrap())
                        .unwrap_or(1);
                    let width = match e.attrs["type"].as_str() {
                        "Float64" | "Int64" => 8,
                        "Int32" => 4,
                        "UInt8" => 1,
                        t => panic!("{f}: {name}: unexpected type {t}"),
                    };
                    let tuples = match (section.as_str(), name.as_str()) {
                        ("Points", _) | ("PointData", _) => n_points,
                        ("Cells", "connectivity") => {
                            // Q8 cells: eight point indices each.
                            8 * n_cells
                        }
                        ("Cells", _) | ("CellData", _) => n_cells,
                        _ => panic!("{f}: DataArray {name} outside a known section"),
                    };
                    assert_eq!(
                        count,
                        tuples * comps * width,
                        "{f}: {section}/{name}: {count} bytes for {tuples} tuples × {comps} × {width}"
                    );
                    arrays.insert(format!("{section}/{name}"), data);
                }
                _ => {}
            }
        }
        // Points, 3 cell arrays, 5 point arrays, and at least the 3 continuum cell-data
        // arrays (region, stress, strain; concrete state arrays may follow).
        assert!(n_arrays >= 12, "{f}: {n_arrays} arrays");
        // The box beam is elastic: no point can crack or crush, so no concrete state arrays.
        for name in [
            "cracks",
            "crack_angle",
            "crack_normal",
            "plastic_strain",
            "crushed",
        ] {
            assert!(
                !arrays.contains_key(&format!("CellData/{name}")),
                "{f}: elastic model wrote CellData/{name}"
            );
        }
        let f64s = |key: &str| -> Vec<f64> {
            arrays[key]
                .chunks(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                .collect()
        };
        // Decoded values make sense: the points span the beam, cells are Q8 (VTK 23).
        let pts = f64s("Points/Points");
        let max_x = pts.chunks(3).map(|p| p[0]).fold(f64::MIN, f64::max);
        let max_y = pts.chunks(3).map(|p| p[1]).fold(f64::MIN, f64::max);
        // Generated coordinates: length·i/n, exact to a few ulps.
        assert!(
            (max_x - SPAN).abs() < 1e-12 && (max_y - 0.6).abs() < 1e-12,
            "{max_x} {max_y}"
        );
        assert!(
            arrays["Cells/types"].iter().all(|&t| t == 23),
            "{f}: Q8 is VTK type 23"
        );
        // Int32 indices (the mesh is far below 2³¹ points).
        let offsets: Vec<i32> = arrays["Cells/offsets"]
            .chunks(4)
            .map(|b| i32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(offsets.len(), n_cells);
        assert_eq!(offsets.last(), Some(&(8 * n_cells as i32)));
        // The vertical reactions of all nodes balance the applied load of that increment:
        // W + 2 × 1 kN × Q. 1e-6 relative: equilibrium to the solver residual plus round-off.
        let q = h.column("factor:Q")[k];
        let ry: f64 = f64s("PointData/reaction").chunks(3).map(|r| r[1]).sum();
        let applied = weight + 2.0e3 * q;
        assert!(
            rel(ry, applied) < 1e-6,
            "{f}: ΣRy = {ry}, applied {applied}"
        );
        // The displacement field holds the monitored midspan deflection (bottom, x = 3.6).
        let uy_mid = pts
            .chunks(3)
            .zip(f64s("PointData/displacement").chunks(3))
            .find(|(p, _)| (p[0] - 3.6).abs() < 1e-9 && p[1].abs() < 1e-9)
            .map(|(_, u)| u[1])
            .expect("a node at (3.6, 0)");
        assert_eq!(uy_mid, h.column("midspan_uy")[k], "{f}");
    }
}

#[test]
fn steps_without_field_output_give_the_same_history() {
    // output = "none" on every step (and --no-fields): history and monitors bit for bit those of the run
    // with field files (the fields are written after each increment, never read back), and
    // no .vtu or results.pvd; the report still builds from the history.
    let tmp = TempDir::new("nofields");
    let (text, _) = run_box_beam(&tmp);
    let n_steps = steps_of(&text).len();
    let mut none = String::new();
    for line in text.lines() {
        if !line.trim_start().starts_with("output") {
            none.push_str(line);
            none.push('\n');
        }
        if line.trim() == "[[steps]]" {
            none.push_str("output = \"none\"\n");
        }
    }
    std::fs::write(tmp.join("none.toml"), none).unwrap();
    let o = segfem(tmp.path(), &["run", "none.toml", "-o", "none"]);
    assert_eq!(code(&o), 0, "run failed: {}", stderr(&o));
    let (with, without) = (tmp.join("out"), tmp.join("none"));
    assert_eq!(
        read(&with.join("history.csv")),
        read(&without.join("history.csv"))
    );
    let monitors = |d: &Path| {
        let s: serde_json::Value = serde_json::from_str(&read(&d.join("summary.json"))).unwrap();
        s["final_monitors"].clone()
    };
    assert_eq!(monitors(&with), monitors(&without));
    let mut have: Vec<String> = std::fs::read_dir(&without)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    have.sort();
    assert_eq!(have, ["checkpoint.bin", "history.csv", "summary.json"]);
    assert!(n_steps > 1, "the example has several steps");
    // --no-fields on the model as given: the same.
    let o = segfem(tmp.path(), &["run", "f.toml", "-o", "nf", "--no-fields"]);
    assert_eq!(code(&o), 0, "run failed: {}", stderr(&o));
    assert_eq!(
        read(&with.join("history.csv")),
        read(&tmp.join("nf").join("history.csv"))
    );
    assert!(!tmp.join("nf").join("results.pvd").exists());
    let o = segfem(tmp.path(), &["report", "none", "-o", "r.html"]);
    assert_eq!(code(&o), 0, "report failed: {}", stderr(&o));
    let html = read(&tmp.join("r.html"));
    assert!(
        html.contains("output = &quot;none&quot;"),
        "the report says why it has no drawings"
    );
}

#[test]
fn cantilever_matches_beam_theory() {
    let tmp = TempDir::new("cantilever");
    assert_eq!(
        code(&segfem(
            tmp.path(),
            &["example", "cantilever", "-o", "c.toml"]
        )),
        0
    );
    // Default output directory: the model name without extension, beside it.
    let o = segfem(tmp.path(), &["run", "c.toml"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let h = History::parse(&read(&tmp.join("c/history.csv")));
    assert_eq!(h.rows.len(), 1, "one linear step of one increment");
    // Total end shear P = q h = 20 kN/m × 0.5 m = 10 kN, carried by the wall (upward, +).
    // 1e-9 relative: a linear solve, reactions equal the consistent edge load to round-off.
    let p = 20e3 * 0.5;
    let ry = h.column("wall_Ry")[0];
    assert!(rel(ry, p) < 1e-9, "wall Ry = {ry}");
    // Tip deflection: P L³/(3EI) + P L/(κ G A) (Timoshenko beam, κ = 5/6). The clamped wall
    // (every node fixed) is a little stiffer than the beam's clamp, so allow 3 %.
    let (e, nu, l, t, d): (f64, f64, f64, f64, f64) = (200e9, 0.3, 4.0, 0.1, 0.5);
    let i = t * d * d * d / 12.0;
    let g = e / (2.0 * (1.0 + nu));
    let beam = p * l.powi(3) / (3.0 * e * i) + p * l / (5.0 / 6.0 * g * t * d);
    let tip = h.column("tip_uy")[0];
    assert!(
        rel(-tip, beam) < 0.03,
        "tip uy = {tip}, beam theory {}",
        -beam
    );
}

#[test]
fn no_convergence_exits_3_and_keeps_results() {
    // An elastic model cannot fail to converge on its own; a tolerance no residual can
    // meet with a single allowed iteration and no cuts makes the second (load) step fail,
    // while the first (linear) step converges on the energy criterion.
    let tmp = TempDir::new("noconv");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/box-beam.toml"),
    )
    .unwrap();
    let first = "name = \"self_weight\"\nkind = \"load\"";
    assert_eq!(text.matches(first).count(), 1);
    let text = text.replace(first, "name = \"self_weight\"\nkind = \"linear\"")
        + "\n[solver]\nforce_tolerance = 1e-14\nmax_iterations = 1\nmax_cuts = 0\n";
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out"]);
    assert_eq!(code(&o), 3, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("error: m.toml: step 'service' did not converge"),
        "{err}"
    );
    assert!(
        err.contains("results up to the last converged increment are in out"),
        "{err}"
    );
    // Results so far are kept: the first step's increment in history, field and summary.
    let h = History::parse(&read(&tmp.join("out/history.csv")));
    assert_eq!(h.rows.len(), 1);
    let r = h.column("R_left")[0];
    assert!(rel(r, RHO * G * AREA * SPAN / 2.0) < 1e-6, "R_left {r}");
    let pvd = parse_xml(&read(&tmp.join("out/results.pvd"))).unwrap();
    let files: Vec<&str> = pvd
        .iter()
        .filter(|e| e.name == "DataSet")
        .map(|e| e.attrs["file"].as_str())
        .collect();
    assert_eq!(files, ["step001_inc0001.vtu"]);
    assert!(tmp.join("out/step001_inc0001.vtu").is_file());
    let s: serde_json::Value = serde_json::from_str(&read(&tmp.join("out/summary.json"))).unwrap();
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("did not converge"));
}

#[test]
fn unwritable_output_exits_1() {
    let tmp = TempDir::new("io");
    assert_eq!(
        code(&segfem(
            tmp.path(),
            &["example", "cantilever", "-o", "c.toml"]
        )),
        0
    );
    // The output "directory" is an existing file: it cannot be created.
    std::fs::write(tmp.join("blocker"), "x").unwrap();
    let o = segfem(tmp.path(), &["run", "c.toml", "-o", "blocker"]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.starts_with("error: blocker"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(read(&tmp.join("blocker")), "x");
}

#[test]
fn solve_time_mechanism_exits_2() {
    // Two Q4 elements touching at one corner node (node 3): the supports hold the first
    // completely, but the second can rotate about the shared node. The rigid-body check of
    // the input sees one connected part with all three motions held, so `check` accepts it;
    // the solve finds the zero pivot.
    let tmp = TempDir::new("hinge");
    let model = r#"
[[materials]]
name = "c"
kind = "elastic"
E = 30e9
nu = 0.2

[[regions]]
name = "r"
material = "c"
thickness = 0.2

[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]]
blocks = [{ region = "r", element = "Q4", elements = [[1, 2, 3, 4], [3, 5, 6, 7]] }]

[[supports]]
name = "base"
line = [[0.0, 0.0], [1.0, 0.0]]
ux = 0.0
uy = 0.0

[[load_cases]]
name = "P"
point_loads = [{ node = 6, force = [0.0, -1.0e3] }]

[[steps]]
name = "s"
kind = "linear"
loads = { P = 1.0 }
"#;
    std::fs::write(tmp.join("m.toml"), model).unwrap();
    assert_eq!(code(&segfem(tmp.path(), &["check", "m.toml"])), 0);
    // Files of an earlier run in the directory: removed, and the terminal says so even
    // though the run fails.
    std::fs::create_dir_all(tmp.join("out")).unwrap();
    std::fs::write(tmp.join("out/history.csv"), "old").unwrap();
    std::fs::write(tmp.join("out/step001_inc0001.vtu"), "old").unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 2, "{err}");
    assert!(
        lines[0].starts_with("warning: out: removed 2 files of an earlier run"),
        "{err}"
    );
    assert!(!tmp.join("out/step001_inc0001.vtu").exists());
    let err = lines[1];
    assert!(err.starts_with("error: m.toml: "), "{err}");
    assert!(err.contains("mechanism"), "{err}");
    let s: serde_json::Value = serde_json::from_str(&read(&tmp.join("out/summary.json"))).unwrap();
    assert_eq!(s["status"], "failed");
}

/// The TOML keys of the model-file tables: every `pub` field of a struct marked
/// `deny_unknown_fields` in `text` (under its serde `rename`).
fn table_keys(text: &str) -> Vec<String> {
    let mut keys = Vec::new();
    let mut in_table = false;
    let mut marked = false;
    let mut rename: Option<String> = None;
    for line in text.lines().map(str::trim) {
        if line.contains("deny_unknown_fields") {
            marked = true;
        } else if line.starts_with("pub struct ") {
            in_table = marked;
            marked = false;
        } else if line == "}" {
            in_table = false;
        } else if let Some(r) = line.strip_prefix("#[serde(rename = \"") {
            rename = r.split('"').next().map(str::to_string);
        } else if let Some(f) = line.strip_prefix("pub ") {
            if let Some((name, _)) = f.split_once(':') {
                if in_table && !name.contains(' ') {
                    keys.push(rename.take().unwrap_or_else(|| name.to_string()));
                }
            }
            rename = None;
        }
    }
    keys
}

#[test]
fn every_schema_key_is_documented() {
    // Each field of every model-file table (under its TOML name) appears as `key` in
    // docs/input.md: the tables of schema.rs and those kept beside their builders (the
    // [viaduct] generator, …): every source file under src/input/.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let docs = read(&root.join("docs/input.md"));
    let mut files = Vec::new();
    let mut dirs = vec![root.join("src/input")];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                files.push(p);
            }
        }
    }
    let mut keys = Vec::new();
    for f in &files {
        keys.extend(table_keys(&read(f)));
    }
    // schema.rs alone holds more than 40, the generators more than 80 (the material keys
    // are the kinds' schemas, checked by `every_material_key_is_documented_for_its_kind`).
    assert!(keys.len() > 120, "table fields found: {keys:?}");
    // One key of each kind of file: schema.rs, the generator.
    for k in ["relaxation_class", "segment_length"] {
        assert!(keys.iter().any(|x| x == k), "{k} not found among {keys:?}");
    }
    let missing: Vec<&String> = keys
        .iter()
        .filter(|k| {
            // `key`, or the last part of a documented path such as `bands[].depth`.
            !docs.contains(&format!("`{k}`")) && !docs.contains(&format!(".{k}`"))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "keys missing from docs/input.md: {missing:?}"
    );
}

/// The sections of docs/input.md (`#` headings outside code blocks): (heading line, level,
/// text up to the next heading of the same or a higher level).
fn doc_sections(docs: &str) -> Vec<(String, usize, String)> {
    let mut heads = Vec::new();
    let mut fenced = false;
    let lines: Vec<&str> = docs.lines().collect();
    for (n, l) in lines.iter().enumerate() {
        if l.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && l.starts_with('#') {
            let level = l.chars().take_while(|c| *c == '#').count();
            heads.push((n, level));
        }
    }
    heads
        .iter()
        .map(|&(n, level)| {
            let end = heads
                .iter()
                .find(|&&(m, l)| m > n && l <= level)
                .map_or(lines.len(), |&(m, _)| m);
            (lines[n].to_string(), level, lines[n..end].join("\n"))
        })
        .collect()
}

/// Every key of every material kind, from the kinds' own schemas (src/input/build/materials/),
/// appears as `key` in the docs/input.md section whose heading names the kind
/// (`kind = "concrete"`), keys of inline tables (`viscoplastic`) included; a number's own
/// table row gives its schema unit; and the section's `thermal_expansion` line gives the kind's
/// default (10e-6, 12e-6, or none).
#[test]
fn every_material_key_is_documented_for_its_kind() {
    use segfem::input::build::{KeyType, MaterialKind};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let docs = read(&root.join("docs/input.md"));
    let sections = doc_sections(&docs);
    let mut checked = 0;
    let mut missing = Vec::new();
    let mut wrong_units = Vec::new();
    let mut units_checked = 0;
    for kind in MaterialKind::ALL {
        let schema = kind.schema();
        let tag = format!("`kind = \"{}\"`", schema.name);
        let body: Vec<&str> = sections
            .iter()
            .filter(|(head, _, _)| head.contains(&tag))
            .map(|(_, _, text)| text.as_str())
            .collect();
        assert!(!body.is_empty(), "no docs/input.md heading names {tag}");
        let body = body.join("\n");
        let mut keys: Vec<&str> = Vec::new();
        for k in schema.keys {
            keys.push(k.name);
            if let KeyType::Table(sub) = k.ty {
                keys.extend(sub.iter().map(|s| s.name));
            }
        }
        for k in keys {
            checked += 1;
            if !body.contains(&format!("`{k}`")) {
                missing.push(format!("{}.{k}", schema.name));
            }
        }
        // A number with a row of its own (`| `key` | ...`) gives the schema's unit in a cell
        // (`-` and `–` both mean none; the concrete table gives the type of other keys there).
        let mut rows = Vec::new();
        for k in schema.keys {
            rows.push(k);
            if let KeyType::Table(sub) = k.ty {
                rows.extend(sub.iter());
            }
        }
        for k in rows.into_iter().filter(|k| matches!(k.ty, KeyType::Number)) {
            let head = format!("| `{}`", k.name);
            let own_row = |l: &&str| {
                l.strip_prefix(&head)
                    .is_some_and(|rest| rest.trim_start().starts_with('|'))
            };
            for row in body.lines().filter(own_row) {
                units_checked += 1;
                let cells: Vec<&str> = row.split('|').map(str::trim).collect();
                let unit_cell =
                    |c: &&str| *c == k.unit || (k.unit == "-" && (*c == "-" || *c == "–"));
                if !cells.iter().any(unit_cell) {
                    wrong_units.push(format!("{}.{} [{}]: {row}", schema.name, k.name, k.unit));
                }
            }
        }
        let alpha = body
            .lines()
            .find(|l| l.contains("`thermal_expansion`"))
            .unwrap_or("");
        let want = match schema.thermal_expansion {
            Some(a) => format!("{}e-6", (a * 1e6).round()),
            None => "none".to_string(),
        };
        assert!(
            alpha.contains(&want),
            "{tag}: its thermal_expansion line should give the default {want}: {alpha:?}"
        );
    }
    // elastic 7, elastic_creep 10, concrete 43 + 7 viscoplastic, the steels 4 each.
    assert!(checked >= 75, "{checked} keys checked");
    assert!(
        missing.is_empty(),
        "material keys missing from their kind's section of docs/input.md: {missing:?}"
    );
    // 6 elastic, 7 elastic_creep, 24 concrete rows (viscoplastic's included).
    assert!(units_checked >= 35, "{units_checked} unit cells checked");
    assert!(
        wrong_units.is_empty(),
        "docs/input.md rows without the schema's unit: {wrong_units:#?}"
    );
}

/// A unit that looks wrong (thickness in cm) is a warning: printed by `check` and `run` on
/// standard error, listed in summary.json, and the run completes.
#[test]
fn unit_warning_reaches_stderr_and_summary() {
    let tmp = TempDir::new("unitwarn");
    assert_eq!(
        code(&segfem(
            tmp.path(),
            &["example", "cantilever", "-o", "c.toml"]
        )),
        0
    );
    let text = read(&tmp.join("c.toml"));
    assert_eq!(text.matches("thickness = 0.1\n").count(), 1);
    std::fs::write(
        tmp.join("c.toml"),
        text.replace("thickness = 0.1\n", "thickness = 30.0\n"),
    )
    .unwrap();
    let want = "warning: c.toml: regions[0].thickness: thickness 30 m is outside 0.001–20 m; segfem works in metres (0.3 m, not 30 cm)";
    let o = segfem(tmp.path(), &["check", "c.toml"]);
    assert_eq!(code(&o), 0);
    assert_eq!(stderr(&o).trim_end(), want);
    let o = segfem(tmp.path(), &["run", "c.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert_eq!(stderr(&o).trim_end(), want);
    let s: serde_json::Value = serde_json::from_str(&read(&tmp.join("out/summary.json"))).unwrap();
    let w = s["warnings"].as_array().unwrap();
    assert_eq!(w.len(), 1);
    assert_eq!(format!("warning: {}", w[0].as_str().unwrap()), want);
}

/// Float64 tuples of a DataArray `section/name` in a .vtu written by segfem (binary,
/// UInt32 header).
fn vtu_f64(doc: &str, section: &str, name: &str) -> Vec<f64> {
    let els = parse_xml(doc).expect("well-formed .vtu");
    let mut current = "";
    for e in &els {
        match e.name.as_str() {
            "Points" | "Cells" | "PointData" | "CellData" => current = &e.name,
            "DataArray" if current == section && e.attrs["Name"] == name => {
                let raw = base64_decode(e.text.trim()).expect("base64");
                return match e.attrs["type"].as_str() {
                    "Float64" => raw[4..]
                        .chunks(8)
                        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                        .collect(),
                    "Int32" => raw[4..]
                        .chunks(4)
                        .map(|b| i32::from_le_bytes(b.try_into().unwrap()) as f64)
                        .collect(),
                    t => panic!("{section}/{name}: type {t}"),
                };
            }
            _ => {}
        }
    }
    panic!("no DataArray {section}/{name}")
}

/// One 0.1 m Q4 of C30 pulled in x to ε = 1e-3, ten times its cracking strain: the
/// Gauss-point file has the four points at (1 ± 1/√3)·0.05 m, each with one crack whose
/// normal is x, a crack strain between ε − f_tm/E_ci and ε (the concrete between cracks
/// unloads elastically), and σx equal to the control force over the section.
#[test]
fn gauss_point_file_shows_each_crack() {
    let tmp = TempDir::new("gauss");
    let model = r#"
[[materials]]
name = "c30"
kind = "concrete"
fcm = 38e6
nu = 0.2

[[regions]]
name = "r"
material = "c30"
thickness = 0.1

[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]
blocks = [{ region = "r", element = "Q4", elements = [[1, 2, 3, 4]] }]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.1]]
ux = 0.0

[[supports]]
name = "pin"
node = 1
uy = 0.0

[[steps]]
name = "pull"
kind = "displacement"
control = { line = [[0.1, 0.0], [0.1, 0.1]], component = "x", value = 1e-4 }
increments = 20
"#;
    std::fs::write(tmp.join("m.toml"), model).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let out = tmp.join("out");
    let pvd = read(&out.join("results.pvd"));
    assert!(
        pvd.contains(r#"part="3" file="gauss_step001_inc0020.vtu""#),
        "{pvd}"
    );
    let doc = read(&out.join("gauss_step001_inc0020.vtu"));
    let pts = vtu_f64(&doc, "Points", "Points");
    assert_eq!(pts.len(), 12, "four points");
    let a = 0.05 * (1.0 - 1.0 / 3f64.sqrt());
    let b = 0.05 * (1.0 + 1.0 / 3f64.sqrt());
    for p in pts.chunks(3) {
        for c in &p[..2] {
            assert!(
                (c - a).abs() < 1e-12 || (c - b).abs() < 1e-12,
                "Gauss point {p:?}"
            );
        }
    }
    let eps = 1e-3;
    // MC90 for fcm = 38 MPa: E_ci = 21.5e3 (fcm/10)^(1/3) MPa, f_tm = 1.4 ((fcm − 8)/10)^(2/3) MPa.
    let e_ci = 21.5e9 * (3.8f64).cbrt();
    let f_tm = 1.4e6 * (3.0f64).powf(2.0 / 3.0);
    let cracks = vtu_f64(&doc, "PointData", "cracks");
    let normal = vtu_f64(&doc, "PointData", "crack_normal");
    let opening = vtu_f64(&doc, "PointData", "crack_strains");
    let stress = vtu_f64(&doc, "PointData", "stress");
    let h = History::parse(&read(&out.join("history.csv")));
    let force = *h.column("control_force").last().unwrap();
    for g in 0..4 {
        assert_eq!(cracks[g], 1.0, "point {g}: one crack");
        assert!(
            (normal[3 * g].abs() - 1.0).abs() < 1e-9,
            "normal {:?}",
            &normal[3 * g..3 * g + 3]
        );
        let w = opening[2 * g];
        assert!(
            w <= eps && w >= eps - f_tm / e_ci,
            "point {g}: crack strain {w:e} outside [{:e}, {eps:e}]",
            eps - f_tm / e_ci
        );
        assert_eq!(opening[2 * g + 1], 0.0, "no second crack");
        // Uniform field: every point carries the section's mean stress (1e-6: equilibrium
        // tolerance of the iterations).
        let sx = force / (0.1 * 0.1);
        assert!(
            (stress[3 * g] - sx).abs() <= 1e-6 * f_tm,
            "σx {} vs F/A {sx}",
            stress[3 * g]
        );
    }
}
