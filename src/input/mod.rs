//! Model-file input: TOML schema, parsing with line numbers, validation into a [`Model`].

pub mod build;
pub mod error;
pub mod locate;
pub mod schema;

pub use build::Built;
use error::Ctx;
pub use error::InputError;
use std::path::Path;

/// Read and validate a model file.
pub fn load(path: &Path) -> Result<Built, InputError> {
    let label = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: label.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    parse(&text, &label)
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
        let key = e
            .span()
            .map(|s| text.get(s.clone()).unwrap_or("").trim().to_string())
            .filter(|k| !k.is_empty() && k.len() < 60 && !k.contains('\n'))
            .unwrap_or_default();
        InputError {
            file: label.to_string(),
            line,
            key,
            message: e.message().trim().replace('\n', " "),
        }
    })?;
    build::build(file, &ctx)
}
