//! Construction stages in the analysis (docs/theory-stages.md): which elements act in the
//! current step, the displacements they were born at, the equations held because no active
//! element (or an active staged support) moves them, and the reactions of removed supports
//! released as loads over the removal step.
//!
//! An element activated after the first step is stress-free where the structure stands when
//! it is placed: its strains are measured from the nodal displacements at activation
//! (`element_ref`), subtracted when the assembly gathers its displacements. Dofs touched by
//! no active element are held where they are, as are the dofs of an active staged support:
//! their rows and columns of the tangent are replaced by a unit diagonal and their residual
//! by zero, so the equation numbering and sparsity pattern stay those of the whole model.

use super::one_way::OneWay;
use super::staged::{same_count, Mismatch, StateBlock};
use crate::fem::dofs::CONSTRAINED;
use crate::linalg::pattern::LowerPattern;
use crate::model::Model;

/// The stage the analysis is in and what it implies for the assembly. Saved in the
/// checkpoint: the reference displacements of the parts born after the first step are
/// known only from the run that placed them.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StageState {
    /// Index of the step whose stage is set (None before the first).
    pub step: Option<usize>,
    /// Whether each continuum element acts.
    pub element_active: Vec<bool>,
    /// Displacements of each element's nodes when it was activated after the first step
    /// (interleaved x, y per node) [m]; None: born with the structure (reference zero).
    pub element_ref: Vec<Option<Vec<f64>>>,
    /// Whether each joint contact element acts (all its nodes on active elements).
    pub interface_active: Vec<bool>,
    /// Displacements of each contact element's nodes when it was activated after the first
    /// step [m] (None: from the start).
    pub interface_ref: Vec<Option<Vec<f64>>>,
    /// Equations held where they are in this stage (index = equation).
    pub held: Vec<bool>,
    /// Reactions of the supports removed at the start of this step (all dofs) [N], released
    /// linearly over the step: the load (1 − level) · release is added to the external
    /// forces.
    pub release: Vec<f64>,
    /// Equations held for other reasons than a one-way support's contact (no active
    /// element, an active two-way staged support); `held` adds the touching contact points.
    pub base_held: Vec<bool>,
    /// The contact points of the one-way supports and their statuses.
    pub one_way: OneWay,
}

/// What a [`StageState`] is checked against: the model and its numbers of equations and
/// dofs.
#[derive(Clone, Copy)]
pub struct StageShape<'a> {
    /// The model.
    pub model: &'a Model,
    /// Number of free equations.
    pub n_eq: usize,
    /// Number of dofs.
    pub n_dofs: usize,
}

impl StateBlock for StageState {
    type Shape<'a> = StageShape<'a>;

    /// The trial statuses of the one-way supports become the committed ones (the rest of
    /// the stage changes only between steps, [`StageState::enter`]).
    fn commit(&mut self) {
        self.one_way.commit();
    }

    /// Back to the committed statuses of the one-way supports, the held equations with
    /// them.
    fn revert(&mut self) {
        self.revert_contacts();
    }

    /// One entry per element, joint element, equation and dof of the model, and one-way
    /// contact points if (and only if) the model has one-way supports.
    fn check_shape(&self, saved: &Self, shape: StageShape<'_>) -> Result<(), Mismatch> {
        let StageShape {
            model,
            n_eq,
            n_dofs,
        } = shape;
        let (n_el, n_if) = (model.elements.len(), model.interfaces.len());
        same_count("staged elements", saved.element_active.len(), n_el)?;
        same_count("staged element references", saved.element_ref.len(), n_el)?;
        same_count("staged joint elements", saved.interface_active.len(), n_if)?;
        same_count("staged joint references", saved.interface_ref.len(), n_if)?;
        same_count("staged equations", saved.held.len(), n_eq)?;
        same_count("staged releases", saved.release.len(), n_dofs)?;
        same_count("staged base equations", saved.base_held.len(), n_eq)?;
        let one_way = model.staging.has_one_way();
        if saved.step.is_some() && one_way == saved.one_way.points.is_empty() {
            return Err(
                "the checkpoint and the model differ in their one-way supports: the model changed since the checkpoint was written".into(),
            );
        }
        Ok(())
    }
}

/// Displacements [m] of `nodes` in `u`, interleaved.
fn gather(nodes: &[usize], u: &[f64]) -> Vec<f64> {
    nodes
        .iter()
        .flat_map(|&n| [u[2 * n], u[2 * n + 1]])
        .collect()
}

impl StageState {
    /// Whether continuum element `e` acts.
    pub fn element_acts(&self, e: usize) -> bool {
        self.element_active[e]
    }

    /// Set the stage of step `step` at displacements `u` [m]; `eq` maps dofs to equations.
    /// Elements and contact elements that start to act take `u` as their reference;
    /// supports removed now leave `reaction` (f_int − f_ext at their dofs, all dofs [N]) as
    /// the load to release over the step.
    pub fn enter(
        &mut self,
        model: &Model,
        step: usize,
        u: &[f64],
        eq: &[usize],
        reaction: Option<&[f64]>,
    ) {
        let st = &model.staging;
        let first = self.step.is_none();
        let n_el = model.elements.len();
        self.element_active.resize(n_el, false);
        self.element_ref.resize(n_el, None);
        for (e, el) in model.elements.iter().enumerate() {
            let acts = st.region(el.region).active_in(step);
            if acts && !self.element_active[e] && !first {
                self.element_ref[e] = Some(gather(&el.nodes, u));
            }
            self.element_active[e] = acts;
        }
        let mut alive = vec![false; model.nodes.len()];
        for (e, el) in model.elements.iter().enumerate() {
            if self.element_active[e] {
                el.nodes.iter().for_each(|&n| alive[n] = true);
            }
        }
        let n_if = model.interfaces.len();
        self.interface_active.resize(n_if, false);
        self.interface_ref.resize(n_if, None);
        for (i, itf) in model.interfaces.iter().enumerate() {
            let acts = itf.nodes.iter().all(|&n| alive[n]);
            if acts && !self.interface_active[i] && !first {
                self.interface_ref[i] = Some(gather(&itf.nodes, u));
            }
            self.interface_active[i] = acts;
        }
        let n_eq = eq.iter().filter(|&&q| q != CONSTRAINED).count();
        self.held = vec![false; n_eq];
        for (d, &q) in eq.iter().enumerate() {
            if q != CONSTRAINED && !alive[d / 2] {
                self.held[q] = true;
            }
        }
        self.release = vec![0.0; u.len()];
        for (s, sp) in model.supports.iter().enumerate() {
            let l = st.support(s);
            if !st.support_is_staged(s) {
                continue;
            }
            for &(n, dir, _) in &sp.dofs {
                let d = 2 * n + dir.index();
                let q = eq[d];
                if q == CONSTRAINED {
                    continue;
                }
                // A one-way support's pushing dof is held by its contact status.
                let one_way = st.push(s).is_some_and(|p| p.dir() == dir);
                if l.active_in(step) && !one_way {
                    self.held[q] = true;
                } else if l.until == Some(step) {
                    if let Some(r) = reaction {
                        self.release[d] = r[d];
                    }
                }
            }
        }
        self.base_held = self.held.clone();
        self.one_way.enter(model, step, u, eq, &alive);
        self.held = self.one_way.held(&self.base_held);
        self.step = Some(step);
    }

    /// Set the held equations from the trial statuses of the one-way supports.
    pub fn apply_contacts(&mut self) {
        if !self.one_way.points.is_empty() {
            self.held = self.one_way.held(&self.base_held);
        }
    }

    /// Back to the committed statuses of the one-way supports (a thrown-away attempt).
    pub fn revert_contacts(&mut self) {
        if self.one_way.changed() {
            self.one_way.revert();
            self.apply_contacts();
        }
    }

    /// Whether a support is removed at the start of step `step` (the reactions must then be
    /// computed before [`StageState::enter`]).
    pub fn removes_support(model: &Model, step: usize) -> bool {
        (0..model.supports.len()).any(|s| model.staging.support(s).until == Some(step))
    }

    /// Replace the rows and columns of the held equations in the lower-triangle tangent
    /// `k` of `pattern` by a unit diagonal (their corrections are then zero).
    pub fn hold_tangent(&self, pattern: &LowerPattern, k: &mut [f64]) {
        for j in 0..pattern.n {
            for p in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[p];
                if self.held[i] || self.held[j] {
                    k[p] = if i == j { 1.0 } else { 0.0 };
                }
            }
        }
    }

    /// Zero the free-equation entries of the held equations (their residuals).
    pub fn hold_free(&self, free: &mut [f64]) {
        for (v, &h) in free.iter_mut().zip(&self.held) {
            if h {
                *v = 0.0;
            }
        }
    }

    /// Add the released reactions at `level` ∈ [0, 1] of the step to `f_ext` [N].
    pub fn add_release(&self, f_ext: &mut [f64], level: f64) {
        let s = 1.0 - level;
        if s > 0.0 {
            for (f, r) in f_ext.iter_mut().zip(&self.release) {
                *f += s * r;
            }
        }
    }
}
