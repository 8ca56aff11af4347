//! docs/errors.md is a table of test cases: every entry's change is applied to its base
//! model, `segfem check` is run on it, and the message must be exactly the one documented
//! (errors: exit status 2 and that one line; warnings: exit status 0 and those warning
//! lines). The documentation and the program therefore cannot drift apart.

mod common;

use common::{code, segfem, stderr, TempDir};
use std::collections::HashMap;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// One catalogue entry.
struct Entry {
    title: String,
    base: String,
    /// (removed, added); removed empty = append.
    edits: Vec<(String, String)>,
    expected: Vec<String>,
}

/// Fenced blocks of a markdown text: (info string, content), in order.
fn blocks(md: &str) -> Vec<(String, String, String)> {
    let mut out = Vec::new();
    let mut title = String::new();
    let mut lines = md.lines();
    while let Some(l) = lines.next() {
        if let Some(t) = l.strip_prefix("### ") {
            title = t.to_string();
        }
        if let Some(info) = l.strip_prefix("```") {
            let mut body = String::new();
            for b in lines.by_ref() {
                if b == "```" {
                    break;
                }
                body.push_str(b);
                body.push('\n');
            }
            out.push((title.clone(), info.to_string(), body));
        }
    }
    out
}

fn parse(md: &str) -> (HashMap<String, String>, Vec<Entry>) {
    let mut bases = HashMap::new();
    let mut entries = Vec::new();
    let bl = blocks(md);
    let mut i = 0;
    while i < bl.len() {
        let (title, info, body) = &bl[i];
        if info == "toml" {
            if let Some(rest) = body.strip_prefix("# base: ") {
                let (name, text) = rest.split_once('\n').expect("base name line");
                bases.insert(name.to_string(), text.to_string());
            }
        } else if info == "diff" {
            let (first, rest) = body.split_once('\n').expect("diff base line");
            let base = first
                .strip_prefix("# base: ")
                .expect("# base: NAME")
                .to_string();
            let mut edits = Vec::new();
            for part in rest.split("@@\n") {
                let (mut from, mut to) = (Vec::new(), Vec::new());
                for l in part.lines() {
                    if let Some(x) = l.strip_prefix('-') {
                        from.push(x);
                    } else if let Some(x) = l.strip_prefix('+') {
                        to.push(x);
                    } else {
                        panic!("{title}: diff line {l:?}");
                    }
                }
                let join = |v: &[&str]| {
                    if v.is_empty() {
                        String::new()
                    } else {
                        v.join("\n") + "\n"
                    }
                };
                edits.push((join(&from), join(&to)));
            }
            let (_, info2, msg) = &bl[i + 1];
            assert_eq!(info2, "text", "{title}: a text block follows the diff");
            entries.push(Entry {
                title: title.clone(),
                base,
                edits,
                expected: msg.lines().map(str::to_string).collect(),
            });
            i += 1;
        }
        i += 1;
    }
    (bases, entries)
}

/// The base text with the entry's edits. A removal must match exactly once; when the removed
/// text ends a line in the doc but not in the base (last line without newline), the
/// newline-free form is tried.
fn apply(title: &str, base: &str, edits: &[(String, String)]) -> String {
    let mut t = base.to_string();
    for (from, to) in edits {
        if from.is_empty() {
            t.push_str(to);
            continue;
        }
        let (f, to) = if t.matches(from.as_str()).count() == 1 {
            (from.clone(), to.clone())
        } else {
            // A removal given as whole lines may stand for part of a line: retry without the
            // final newline on both sides.
            (
                from.trim_end_matches('\n').to_string(),
                to.trim_end_matches('\n').to_string(),
            )
        };
        assert_eq!(
            t.matches(f.as_str()).count(),
            1,
            "{title}: {f:?} must occur once"
        );
        t = t.replacen(&f, &to, 1);
    }
    t
}

#[test]
fn every_documented_error_and_warning_is_given() {
    let md = std::fs::read_to_string(root().join("docs/errors.md")).unwrap();
    let (mut bases, entries) = parse(&md);
    for ex in [
        "seed-beam-elastic",
        "rc-beam",
        "creep-beam",
        "gmsh-tapered",
        "cantilever",
        "viaduct",
    ] {
        let p = root().join(format!("examples/{ex}.toml"));
        bases.insert(ex.to_string(), std::fs::read_to_string(p).unwrap());
    }
    assert!(entries.len() >= 150, "{} entries", entries.len());
    let tmp = TempDir::new("catalogue");
    std::fs::copy(
        root().join("examples/gmsh-tapered.msh"),
        tmp.join("gmsh-tapered.msh"),
    )
    .unwrap();
    let mut failures = Vec::new();
    for e in &entries {
        let base = bases
            .get(&e.base)
            .unwrap_or_else(|| panic!("{}: no base '{}'", e.title, e.base));
        let text = apply(&e.title, base, &e.edits);
        std::fs::write(tmp.join("bad.toml"), &text).unwrap();
        let o = segfem(tmp.path(), &["check", "bad.toml"]);
        let err = stderr(&o);
        assert!(!err.contains("panicked"), "{}: panic\n{err}", e.title);
        let warning = e.expected[0].starts_with("warning:");
        let got: Vec<String> = if warning {
            err.lines()
                .filter(|l| l.starts_with("warning:"))
                .map(str::to_string)
                .collect()
        } else {
            err.lines().map(str::to_string).collect()
        };
        let want_code = if warning { 0 } else { 2 };
        if code(&o) != want_code || got != e.expected {
            failures.push(format!(
                "{}: exit {} (want {want_code})\n  got:  {got:?}\n  want: {:?}",
                e.title,
                code(&o),
                e.expected
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The base models themselves are valid and give no warning, so that each entry's message
/// comes from its change alone.
#[test]
fn bases_are_valid() {
    let md = std::fs::read_to_string(root().join("docs/errors.md")).unwrap();
    let (bases, _) = parse(&md);
    assert_eq!(bases.len(), 2);
    let tmp = TempDir::new("catalogue-bases");
    for (name, text) in &bases {
        std::fs::write(tmp.join("m.toml"), text).unwrap();
        let o = segfem(tmp.path(), &["check", "m.toml"]);
        assert_eq!(code(&o), 0, "{name}: {}", stderr(&o));
        assert_eq!(stderr(&o), "", "{name}: no warnings");
    }
}
