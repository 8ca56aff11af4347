//! Generators: short input sections expanded into the ordinary tables of the model file
//! before validation, so that a generated model goes through exactly the checks of one
//! written out by hand (docs/input.md, "[viaduct]").
//!
//! A generated table comes first in its list (the user's own entries follow), and an error
//! the validation finds in a generated entry is reported against the generator's section,
//! naming the generated part; an error in one of the user's entries keeps the user's index.

pub mod cantilever;
pub mod viaduct;

use super::error::{Ctx, InputError};
use super::schema::File;

/// How many entries of each list the generators put in front of the user's.
#[derive(Debug, Default, Clone)]
pub struct Generated {
    /// Section that generated them (`"viaduct"`), empty when nothing was generated.
    pub(super) section: &'static str,
    /// Per list (`"supports"`, `"steps"`, …): the names of the generated entries, in
    /// front of the user's.
    pub(super) lists: Vec<(&'static str, Vec<String>)>,
    /// Lists only the generator writes (`"regions"`: the bands, split per segment when
    /// the mesh is built, so their final number is not known here).
    pub(super) owned: Vec<&'static str>,
    /// The generator wrote `[mesh]`.
    pub(super) mesh: bool,
}

/// Expand every generator section of `file` into its ordinary tables.
pub fn expand(mut file: File, ctx: &Ctx) -> Result<(File, Generated), InputError> {
    let mut generated = Generated::default();
    if let Some(v) = file.viaduct.take() {
        generated = viaduct::expand(&v, &mut file, ctx)?;
    }
    Ok((file, generated))
}

impl Generated {
    /// Report `e` against what the user wrote: an error in a generated entry names the
    /// generator's section and the generated part; a user's entry gets its own index back.
    pub fn remap(&self, mut e: InputError) -> InputError {
        if self.section.is_empty() {
            return e;
        }
        if self.mesh && (e.key == "mesh" || e.key.starts_with("mesh.")) {
            e.message = format!("in the generated [mesh] ({}): {}", e.key, e.message);
            e.key = self.section.to_string();
            return e;
        }
        for list in &self.owned {
            let Some(rest) = e.key.strip_prefix(list) else {
                continue;
            };
            if rest.is_empty() || rest.starts_with('[') || rest.starts_with('.') {
                e.message = format!("in the generated {list} ({}): {}", e.key, e.message);
                e.key = self.section.to_string();
                return e;
            }
        }
        for (list, names) in &self.lists {
            let Some(rest) = e.key.strip_prefix(list) else {
                continue;
            };
            let Some(rest) = rest.strip_prefix('[') else {
                continue;
            };
            let Some((index, tail)) = rest.split_once(']') else {
                continue;
            };
            let Ok(i) = index.parse::<usize>() else {
                continue;
            };
            if let Some(name) = names.get(i) {
                e.message = format!(
                    "in the generated {} '{name}' ({}): {}",
                    singular(list),
                    e.key,
                    e.message
                );
                e.key = self.section.to_string();
            } else {
                e.key = format!("{list}[{}]{tail}", i - names.len());
            }
            return e;
        }
        e
    }
}

/// "steps" → "step" for messages.
fn singular(list: &str) -> &str {
    match list {
        "supports" => "support",
        "tendons" => "tendon",
        "load_cases" => "load case",
        "steps" => "step",
        "regions" => "region",
        o => o,
    }
}
