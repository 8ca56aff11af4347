//! Element kinds: plane-stress continuum, embedded bars, joint interfaces and external tendons.
//!
//! Every element family answers through one signature, [`ElementResponse`]: from the nodal
//! displacements and its committed state it writes its internal forces (and, when asked, its
//! tangent) into buffers the caller owns, and its trial state where the caller says. The
//! assembly (`analysis::system`) only splits the work, calls this and scatters the result.

pub mod bar;
pub mod continuum;
pub mod incompatible;
pub mod interface;
pub mod tendon;
pub mod total_lagrangian;

use crate::materials::point::UpdateError;

/// Caller buffers an element writes its response into.
pub struct Response<'a> {
    /// Internal nodal forces [N], (x, y) per node: exactly 2 n entries, all overwritten.
    pub f: &'a mut [f64],
    /// Tangent ∂f/∂u [N/m], dense row-major (2n)², all overwritten; `None` when only the
    /// forces are wanted (a residual check).
    pub k: Option<&'a mut [f64]>,
}

/// One element's answer to a displacement state.
pub trait ElementResponse {
    /// The committed state the response starts from.
    type Committed: ?Sized;
    /// Where the trial state (and point outputs) go.
    type Trial<'t>;

    /// Write the internal forces and (if `into.k` is given) the tangent at the element's
    /// nodal displacements `u` [m] ((ux, uy) per node) into `into`, and the trial state into
    /// `trial`. Returns whether the tangent written is symmetric (joints that slip and
    /// deviators with friction are not); an error when a material point cannot be updated.
    fn response(
        &self,
        u: &[f64],
        committed: &Self::Committed,
        trial: Self::Trial<'_>,
        into: Response<'_>,
    ) -> Result<bool, UpdateError>;
}
