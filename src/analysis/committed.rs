//! What the results read of the analysis state: the committed values, through accessors on
//! [`System`], so that the output code does not depend on how the family blocks
//! ([`super::families`]) lay their state out (which copy is committed, the point offsets of
//! the elements, the order of the bar points). Call them between increments; the trial
//! copies are the increment controller's.

use super::system::System;
use super::tendon_time::TendonTime;
use crate::elements::continuum::GaussOutput;
use crate::elements::interface::InterfacePointState;
use crate::elements::tendon::TendonState;
use crate::materials::point::{PointState, TimeContext};

pub use super::families::BarOutput;

impl System<'_> {
    /// Committed displacements (all dofs, x and y per node) [m].
    pub fn displacements(&self) -> &[f64] {
        &self.disp.committed
    }

    /// Displacements before the last committed increment (all dofs) [m].
    pub fn previous_displacements(&self) -> &[f64] {
        &self.disp.previous
    }

    /// Time interval of the last increment on the analysis clock [d].
    pub fn time_interval(&self) -> TimeContext {
        self.time
    }

    /// Committed material-point states of every continuum point (element by element, Gauss
    /// points within).
    pub fn point_states(&self) -> &[PointState] {
        &self.families.continuum.points.committed
    }

    /// Committed material-point states of continuum element `e` (its Gauss points).
    pub fn element_points(&self, e: usize) -> &[PointState] {
        &self.point_states()[self.gp_offset[e]..self.gp_offset[e + 1]]
    }

    /// Committed Gauss-point outputs (strain [-], stress [Pa]) of every continuum point, in
    /// the order of [`System::point_states`].
    pub fn gauss_outputs(&self) -> &[GaussOutput] {
        &self.families.continuum.gauss.committed
    }

    /// Committed Gauss-point outputs of continuum element `e`.
    pub fn element_gauss(&self, e: usize) -> &[GaussOutput] {
        &self.gauss_outputs()[self.gp_offset[e]..self.gp_offset[e + 1]]
    }

    /// Committed states of the integration points of joint element `i`.
    pub fn joint_points(&self, i: usize) -> &[InterfacePointState] {
        &self.families.joints.points.committed[i]
    }

    /// Committed span states of every external tendon (None before it is stressed).
    pub fn tendon_states(&self) -> &[Option<TendonState>] {
        &self.families.tendons.states.committed
    }

    /// Committed span states of external tendon `t` (None before it is stressed).
    pub fn tendon_state(&self, t: usize) -> Option<&TendonState> {
        self.tendon_states()[t].as_ref()
    }

    /// Relaxation and loss record of external tendon `t` (None before its first increment
    /// after stressing).
    pub fn tendon_time(&self, t: usize) -> Option<&TendonTime> {
        self.families.tendons.time[t].as_ref()
    }

    /// Committed outputs of every embedded-bar point with its bar and its point index in the
    /// bar (in host-element order).
    pub fn bar_outputs(&self) -> impl Iterator<Item = ((usize, usize), &BarOutput)> {
        (self.bar_gps.iter().copied()).zip(&self.families.bars.out.committed)
    }
}
