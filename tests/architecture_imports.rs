//! Floors that run one way (docs/architecture.md, "Floors and data flow"): every path into
//! another top-level module of the crate (`use crate::x::…`, `crate::x::…` in code,
//! `segfem::x::…` in the binary's `src/main.rs` and `src/cli/`) must be one the import table
//! of docs/architecture.md allows. The table is parsed from the page, so the page and the
//! check cannot drift apart. Unit-test modules (`#[cfg(test)]`) are left out: they are not
//! part of the library and may use any module as a fixture. A second check: the files of
//! `src/analysis/` import each other without a circle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The row of the table that lets a module import anything (the binary).
const ANY: &str = "any";

/// The import table of docs/architecture.md: module → the modules it may import (`ANY`: all).
fn allowed_from_docs(text: &str) -> Result<BTreeMap<String, BTreeSet<String>>, String> {
    let start = text
        .find("| module | may import | why |")
        .ok_or("docs/architecture.md: no table headed `| module | may import | why |`")?;
    let mut table = BTreeMap::new();
    for line in text[start..].lines().skip(2) {
        if !line.starts_with('|') {
            break;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 {
            return Err(format!(
                "docs/architecture.md: table row without 3 cells: {line}"
            ));
        }
        let names = backticked(cells[1]);
        let [module] = names.as_slice() else {
            return Err(format!(
                "docs/architecture.md: first cell must name one module in backticks: {line}"
            ));
        };
        let may: BTreeSet<String> = if cells[2] == ANY {
            [ANY.to_string()].into()
        } else if cells[2] == "—" {
            BTreeSet::new()
        } else {
            let m: BTreeSet<String> = backticked(cells[2]).into_iter().collect();
            if m.is_empty() {
                return Err(format!(
                    "docs/architecture.md: second cell must be `any`, `—` or modules in backticks: {line}"
                ));
            }
            m
        };
        if cells[3].is_empty() {
            return Err(format!(
                "docs/architecture.md: row without a reason: {line}"
            ));
        }
        if table.insert(module.clone(), may).is_some() {
            return Err(format!(
                "docs/architecture.md: module `{module}` twice in the table"
            ));
        }
    }
    if table.is_empty() {
        return Err("docs/architecture.md: the import table has no rows".into());
    }
    Ok(table)
}

/// The words in backticks of a table cell.
fn backticked(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The source with comments and `#[cfg(test)]` items blanked (lines kept, so line numbers
/// stay right), and the files of `#[cfg(test)] mod name;` declarations (`name`).
fn production_code(src: &str) -> (Vec<String>, Vec<String>) {
    let lines: Vec<&str> = src.lines().collect();
    let mut out = Vec::with_capacity(lines.len());
    let mut test_files = vec![];
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim() != "#[cfg(test)]" {
            out.push(strip_comment(lines[i]).to_string());
            i += 1;
            continue;
        }
        // The item the attribute applies to, after any further attributes.
        out.push(String::new());
        i += 1;
        while i < lines.len() && lines[i].trim_start().starts_with("#[") {
            out.push(String::new());
            i += 1;
        }
        let Some(item) = lines.get(i) else { break };
        let code = strip_comment(item).trim_end();
        if let Some(name) = code
            .split_whitespace()
            .skip_while(|w| *w != "mod")
            .nth(1)
            .and_then(|n| n.strip_suffix(';'))
        {
            test_files.push(name.to_string());
        }
        if code.ends_with('{') {
            // rustfmt closes an item at the indentation it opened it.
            let indent = &item[..item.len() - item.trim_start().len()];
            let close = format!("{indent}}}");
            while i < lines.len() && lines[i].trim_end() != close {
                out.push(String::new());
                i += 1;
            }
        }
        out.push(String::new());
        i += 1;
    }
    (out, test_files)
}

/// A line without its `//` comment (doc comments included).
fn strip_comment(line: &str) -> &str {
    line.find("//").map_or(line, |p| &line[..p])
}

/// The top-level modules a line of code names through `root::` (`crate` or `segfem`):
/// `root::x::…` and each first name of `root::{x::…, y, …}`.
fn modules_named(line: &str, root: &str) -> Vec<String> {
    let pat = format!("{root}::");
    let mut out = vec![];
    let mut from = 0;
    while let Some(p) = line[from..].find(&pat) {
        let at = from + p;
        from = at + pat.len();
        let before = line[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        let rest = &line[from..];
        if let Some(group) = rest.strip_prefix('{') {
            // Names at the group's top level: after `{` and after each `,` at depth 0.
            let mut depth = 0;
            let mut start = true;
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && (c.is_alphanumeric() || c == '_') => {
                        out.push(ident(&group[k..]));
                        start = false;
                    }
                    c if !c.is_whitespace() => start = false,
                    _ => {}
                }
            }
        } else {
            let name = ident(rest);
            if !name.is_empty() {
                out.push(name);
            }
        }
    }
    out
}

/// The identifier a string starts with.
fn ident(s: &str) -> String {
    s.chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = vec![];
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let p = e.expect("directory entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// One path into another top-level module: file (relative to src/), line, importing
/// module, imported module.
type Import = (String, usize, String, String);

/// Every import between top-level modules in the production code of `src`.
fn imports(src: &Path) -> Vec<Import> {
    let files = rust_files(src);
    // The files of `#[cfg(test)] mod x;` declarations: x.rs or x/ beside the declaring
    // module's own directory.
    let mut test_only: Vec<PathBuf> = vec![];
    let mut out = vec![];
    let mut parsed = vec![];
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let (code, tests) = production_code(&text);
        let dir = match f.file_name().and_then(|n| n.to_str()) {
            Some("mod.rs") | Some("lib.rs") | Some("main.rs") => f.parent().unwrap().to_path_buf(),
            _ => f.with_extension(""),
        };
        for t in tests {
            test_only.push(dir.join(format!("{t}.rs")));
            test_only.push(dir.join(t));
        }
        parsed.push((f.clone(), code));
    }
    for (f, code) in parsed {
        if test_only.iter().any(|t| f.starts_with(t)) {
            continue;
        }
        let rel = f
            .strip_prefix(src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let first = rel.split('/').next().unwrap().trim_end_matches(".rs");
        let (module, roots): (&str, &[&str]) = match first {
            "lib" => continue,
            // The binary: its own modules are reached through `crate::`, the library's
            // through `segfem::`.
            "main" | "cli" => ("cli", &["segfem"]),
            m => (m, &["crate"]),
        };
        for (n, line) in code.iter().enumerate() {
            for root in roots {
                for m in modules_named(line, root) {
                    if m != module {
                        out.push((rel.clone(), n + 1, module.to_string(), m));
                    }
                }
            }
        }
    }
    out
}

fn manifest() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every import between the crate's top-level modules is one the table of
/// docs/architecture.md allows, and every top-level module has a row.
#[test]
fn imports_follow_the_floors_of_docs_architecture() {
    let root = manifest();
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).unwrap();
    let allowed = allowed_from_docs(&doc).unwrap_or_else(|e| panic!("{e}"));
    let src = root.join("src");
    let mut modules: BTreeSet<String> = BTreeSet::new();
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if p.is_dir() || p.extension().is_some_and(|x| x == "rs") {
            modules.insert(match name.as_str() {
                "main" => "cli".to_string(),
                _ => name,
            });
        }
    }
    modules.remove("lib");
    let missing: Vec<&String> = modules
        .iter()
        .filter(|m| !allowed.contains_key(*m))
        .collect();
    assert!(
        missing.is_empty(),
        "top-level modules without a row in the import table of docs/architecture.md: {missing:?}"
    );
    let stale: Vec<&String> = allowed.keys().filter(|m| !modules.contains(*m)).collect();
    assert!(
        stale.is_empty(),
        "rows of the import table of docs/architecture.md for no module in src/: {stale:?}"
    );
    let found = imports(&src);
    assert!(
        found.len() > 100,
        "only {} imports found: the scan is broken",
        found.len()
    );
    let bad: Vec<String> = found
        .iter()
        .filter(|(_, _, from, to)| {
            let may = &allowed[from];
            !may.contains(ANY) && !may.contains(to)
        })
        .map(|(f, n, from, to)| format!("src/{f}:{n}: {from} imports {to}"))
        .collect();
    assert!(
        bad.is_empty(),
        "imports the table of docs/architecture.md (\"Floors and data flow\") does not allow:\n{}",
        bad.join("\n")
    );
}

/// The files of src/analysis/ (outside unit tests) import each other without a circle:
/// `super::x` and `crate::analysis::x` paths between them form an acyclic graph.
#[test]
fn analysis_files_import_without_a_circle() {
    let dir = manifest().join("src/analysis");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in rust_files(&dir) {
        if f.parent() != Some(dir.as_path()) || f.file_name().is_some_and(|n| n == "mod.rs") {
            continue;
        }
        let name = f.file_stem().unwrap().to_string_lossy().to_string();
        let (code, _) = production_code(&std::fs::read_to_string(&f).unwrap());
        let mut deps = BTreeSet::new();
        for line in &code {
            let line = line.replace("crate::analysis::", "super::");
            deps.extend(modules_named(&line, "super"));
        }
        deps.remove(&name);
        graph.insert(name, deps);
    }
    assert!(graph.len() > 10, "only {} files found", graph.len());
    assert!(
        graph["steps"].contains("system") && graph["families"].contains("staged"),
        "known imports not found: the scan is broken"
    );
    if let Some(circle) = find_circle(&graph) {
        panic!("src/analysis/ imports in a circle: {}", circle.join(" -> "));
    }
}

/// The output code (`src/results/`, `src/cli/`) reads the analysis state through the
/// accessors of `analysis/committed.rs` (docs/architecture.md, "Analysis state"), not through
/// the family and displacement blocks, their committed copies or the point offsets, whose
/// layout is the analysis's own.
#[test]
fn results_read_the_state_through_accessors() {
    let inner = [
        ".families",
        ".gp_offset",
        ".bar_gps",
        ".disp.",
        ".disp)",
        "system.u[",
        "sys.u[",
    ];
    let mut bad = vec![];
    for dir in ["src/results", "src/cli"] {
        for f in rust_files(&manifest().join(dir)) {
            let (code, _) = production_code(&std::fs::read_to_string(&f).unwrap());
            for (i, line) in code.iter().enumerate() {
                if let Some(w) = inner.iter().find(|w| line.contains(*w)) {
                    bad.push(format!("{}:{}: `{w}`", f.display(), i + 1));
                }
            }
        }
    }
    assert!(
        bad.is_empty(),
        "state read past the accessors of analysis/committed.rs:\n{}",
        bad.join("\n")
    );
}

/// A circle of the directed graph (as a path back to its start), if any.
fn find_circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    // Depth-first search; 1 = on the current path, 2 = done.
    fn visit(
        v: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        mark: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        mark.insert(v.to_string(), 1);
        path.push(v.to_string());
        for w in graph.get(v).into_iter().flatten() {
            if !graph.contains_key(w) {
                continue;
            }
            match mark.get(w.as_str()) {
                Some(1) => {
                    let at = path.iter().position(|p| p == w).unwrap();
                    let mut c = path[at..].to_vec();
                    c.push(w.clone());
                    return Some(c);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(w, graph, mark, path) {
                        return Some(c);
                    }
                }
            }
        }
        path.pop();
        mark.insert(v.to_string(), 2);
        None
    }
    let mut mark = BTreeMap::new();
    for v in graph.keys() {
        if !mark.contains_key(v) {
            if let Some(c) = visit(v, graph, &mut mark, &mut vec![]) {
                return Some(c);
            }
        }
    }
    None
}

/// The scanner itself, on hand-written sources whose imports are known: plain and grouped
/// paths are found; comments, `$crate`, identifiers ending in `crate` and unit-test
/// modules are not.
#[test]
fn scanner_finds_the_imports_it_should() {
    let src = "\
use crate::model::Model;
use crate::{analysis::steps, fem::{dofs::DofMap, assembly}, linalg};
// use crate::results::x;
/// [`crate::view`] in a doc comment
let a = crate::input::parse(t); // crate::run in a comment
macro_rules! m { () => { $crate::design::x } }
let b = notcrate::cli::y;
#[cfg(test)]
mod tests {
    use crate::traffic::Traffic;
}
#[cfg(test)]
mod more;
let c = crate::mesh::x;
";
    let (code, tests) = production_code(src);
    assert_eq!(code.len(), src.lines().count());
    assert_eq!(tests, vec!["more".to_string()]);
    let found: Vec<String> = code
        .iter()
        .flat_map(|l| modules_named(l, "crate"))
        .collect();
    assert_eq!(
        found,
        ["model", "analysis", "fem", "linalg", "input", "mesh"].map(String::from)
    );
    // A circle is found, and none in a chain.
    let g = |edges: &[(&str, &str)]| {
        let mut m: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            m.entry(a.to_string()).or_default().insert(b.to_string());
            m.entry(b.to_string()).or_default();
        }
        m
    };
    assert_eq!(find_circle(&g(&[("a", "b"), ("b", "c")])), None);
    assert_eq!(
        find_circle(&g(&[("a", "b"), ("b", "c"), ("c", "a")])),
        Some(["a", "b", "c", "a"].map(String::from).to_vec())
    );
    // The table: a row per module, `—` for none, `any` for all, a reason required.
    let doc = "x\n| module | may import | why |\n|---|---|---|\n\
               | `model` | `materials`, `traffic` | data |\n| `linalg` | — | arrays |\n\
               | `cli` | any | binary |\n\nafter";
    let t = allowed_from_docs(doc).unwrap();
    assert_eq!(t.len(), 3);
    assert!(t["model"].contains("traffic") && t["linalg"].is_empty() && t["cli"].contains(ANY));
    assert!(
        allowed_from_docs("| module | may import | why |\n|---|---|---|\n| `a` | — | |\n").is_err()
    );
}
