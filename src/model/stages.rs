//! Construction stages as plain data: when each staged part of the structure acts. A part
//! is active from the start of the step that activates it up to the start of the step that
//! removes it (docs/theory-stages.md).

use super::Dir;
use serde::{Deserialize, Serialize};

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

/// The way a one-way support (a bearing, a prop, falsework: `supports[i].one_way`) pushes
/// the structure: along +x, −x, +y or −y. It holds its dof in that direction while its
/// reaction on the structure points that way, and lets go when it would pull
/// (docs/theory-stages.md, "One-way supports").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Push {
    /// Pushes along +x.
    PlusX,
    /// Pushes along −x.
    MinusX,
    /// Pushes along +y (a bearing or prop under the structure).
    PlusY,
    /// Pushes along −y.
    MinusY,
}

impl Push {
    /// Every direction, with its model-file spelling.
    pub const ALL: [(Push, &'static str); 4] = [
        (Push::PlusX, "+x"),
        (Push::MinusX, "-x"),
        (Push::PlusY, "+y"),
        (Push::MinusY, "-y"),
    ];

    /// The component it holds.
    pub fn dir(self) -> Dir {
        match self {
            Push::PlusX | Push::MinusX => Dir::X,
            Push::PlusY | Push::MinusY => Dir::Y,
        }
    }

    /// +1 when it pushes along the positive axis, −1 along the negative one.
    pub fn sign(self) -> f64 {
        match self {
            Push::PlusX | Push::PlusY => 1.0,
            Push::MinusX | Push::MinusY => -1.0,
        }
    }

    /// The model-file spelling ("+y", …).
    pub fn name(self) -> &'static str {
        Push::ALL
            .iter()
            .find(|(p, _)| *p == self)
            .map_or("", |(_, n)| n)
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
    /// Per support, the way it pushes if it is one-way (index = support; empty or None:
    /// two-way, a boundary condition that holds both ways).
    pub one_way: Vec<Option<Push>>,
}

impl Staging {
    /// Whether the model has construction stages (some part activated or removed by a
    /// step).
    pub fn is_staged(&self) -> bool {
        !self.regions.is_empty()
    }

    /// Whether some support is one-way (its dofs are then equations whose hold the
    /// analysis switches on and off, [`Staging::one_way`]).
    pub fn has_one_way(&self) -> bool {
        self.one_way.iter().any(Option::is_some)
    }

    /// How support `s` pushes, if it is one-way.
    pub fn push(&self, s: usize) -> Option<Push> {
        self.one_way.get(s).copied().flatten()
    }

    /// Whether the dof of support `s` in direction `dir` is an equation of the analysis
    /// (the support is staged, or one-way in that direction) rather than constrained.
    pub fn support_dof_is_equation(&self, s: usize, dir: Dir) -> bool {
        self.support_is_staged(s) || self.push(s).is_some_and(|p| p.dir() == dir)
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
