//! Model-file input: TOML schema, parsing with line numbers, validation into a [`Model`].

pub mod bar_layers;
pub mod build;
pub mod error;
pub mod generators;
pub mod limits;
pub mod locate;
pub mod schema;
pub mod units;

pub use build::stage_table;
pub use build::Built;
use error::Ctx;
pub use error::InputError;
use std::path::Path;

/// Read and validate a model file.
pub fn load(path: &Path) -> Result<Built, InputError> {
    let label = path.display().to_string();
    let err = |message: String| InputError {
        file: label.clone(),
        line: None,
        key: String::new(),
        message,
    };
    let bytes = limits::read_bounded(path).map_err(err)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        err(format!(
            "cannot read the file: not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })?;
    parse(&text, &label)
}

/// Rust type names in a TOML error said as a user reads them: "expected usize" becomes
/// "expected a whole number ≥ 0", "expected i64" "expected a whole number", "expected f64"
/// "expected a number".
fn plain_types(message: &str) -> String {
    let mut m = message.to_string();
    for (ty, plain) in [
        ("usize", "a whole number ≥ 0"),
        ("u64", "a whole number ≥ 0"),
        ("u32", "a whole number ≥ 0"),
        ("u8", "a whole number ≥ 0"),
        ("i64", "a whole number"),
        ("i32", "a whole number"),
        ("f64", "a number"),
    ] {
        m = m.replace(&format!("expected {ty}"), &format!("expected {plain}"));
    }
    m
}

/// Parse and validate model-file text; `label` names the file in errors.
pub fn parse(text: &str, label: &str) -> Result<Built, InputError> {
    let ctx = Ctx {
        file: label.to_string(),
    };
    let file: schema::File = toml::from_str(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        // The key: the span's text when it is a key (unknown field), otherwise the key
        // written before '=' on the error's line (wrong value type, bad number).
        let span_text = e
            .span()
            .map(|s| text.get(s.clone()).unwrap_or("").trim().to_string())
            .unwrap_or_default();
        let line_text = line
            .and_then(|l| text.lines().nth(l - 1))
            .unwrap_or("")
            .trim();
        let key = match line_text.split_once('=') {
            Some((k, _)) if !k.trim_start().starts_with('[') && !k.contains('{') => {
                k.trim().to_string()
            }
            _ if !span_text.is_empty() && span_text.len() < 60 && !span_text.contains('\n') => {
                span_text
            }
            _ => String::new(),
        };
        InputError {
            file: label.to_string(),
            line,
            key,
            message: plain_types(&e.message().trim().replace('\n', " ")),
        }
    })?;
    let (file, generated) = generators::expand(file, &ctx)?;
    build::build(file, &ctx).map_err(|e| generated.remap(e))
}
pub mod gmsh_mesh;
