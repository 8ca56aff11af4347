//! Construction stages as plain data: when each staged part of the structure acts. A part
//! is active from the start of the step that activates it up to the start of the step that
//! removes it (docs/theory-stages.md).

use serde::Serialize;

/// The steps during which a part acts: from the start of step `from` to the start of step
/// `until` (never removed if None).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Lifetime {
    /// Index of the step at whose start the part is activated (0: from the start).
    pub from: usize,
    /// Index of the step at whose start the part is removed (None: never).
    pub until: Option<usize>,
}

impl Lifetime {
    /// Active from the first step on, never removed.
    pub const ALWAYS: Lifetime = Lifetime {
        from: 0,
        until: None,
    };

    /// Whether the part acts during step `step`.
    pub fn active_in(&self, step: usize) -> bool {
        step >= self.from && self.until.is_none_or(|u| step < u)
    }
}

/// The construction stages of a model: the lifetime of every region and support. Joints
/// act while the regions on both their faces act; embedded bars with their host elements.
/// Empty vectors: the model has no stages (everything acts from the start).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Staging {
    /// Lifetime of each region (index = region), or empty.
    pub regions: Vec<Lifetime>,
    /// Lifetime of each support (index = support), or empty.
    pub supports: Vec<Lifetime>,
}

impl Staging {
    /// Whether the model has construction stages (some part activated or removed by a
    /// step).
    pub fn is_staged(&self) -> bool {
        !self.regions.is_empty()
    }

    /// Lifetime of region `r`.
    pub fn region(&self, r: usize) -> Lifetime {
        self.regions.get(r).copied().unwrap_or(Lifetime::ALWAYS)
    }

    /// Lifetime of support `s`.
    pub fn support(&self, s: usize) -> Lifetime {
        self.supports.get(s).copied().unwrap_or(Lifetime::ALWAYS)
    }

    /// Whether support `s` is activated or removed by a step (its dofs are then equations,
    /// held while it acts, instead of constrained for the whole analysis).
    pub fn support_is_staged(&self, s: usize) -> bool {
        self.support(s) != Lifetime::ALWAYS
    }
}
