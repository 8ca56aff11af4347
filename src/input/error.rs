//! Input errors: one line naming the file, the key (and line where known) and what is wrong.

use std::fmt;

/// A problem with a model file.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// File name as given by the user.
    pub file: String,
    /// 1-based line, where the parser knows it.
    pub line: Option<usize>,
    /// Key path, e.g. `regions[2].thickness`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        if !self.key.is_empty() {
            write!(f, ": {}", self.key)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for InputError {}

/// Context for building errors against one file.
#[derive(Debug, Clone)]
pub struct Ctx {
    /// File label.
    pub file: String,
}

impl Ctx {
    /// An error at `key` with `message`.
    pub fn err(&self, key: impl Into<String>, message: impl Into<String>) -> InputError {
        InputError {
            file: self.file.clone(),
            line: None,
            key: key.into(),
            message: message.into(),
        }
    }
}
