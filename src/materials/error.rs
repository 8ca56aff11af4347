//! Errors of the material point updates.

/// Failure of a material point update. Returned instead of panicking, so that the caller
/// can cut the load/time step and retry from the committed state.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// The implicit return mapping did not converge.
    #[error(
        "return mapping not converged after {iterations} iterations and {substeps} substeps \
         (residual {residual:.3e}, strain [{:.4e}, {:.4e}, {:.4e}])",
        strain[0], strain[1], strain[2]
    )]
    ReturnMappingNotConverged {
        /// Newton iterations spent in the last substep.
        iterations: usize,
        /// Number of substeps of the last attempt.
        substeps: usize,
        /// Last scaled residual norm [-].
        residual: f64,
        /// Total strain (εx, εy, γxy) that was requested [-].
        strain: [f64; 3],
    },
    /// Non-finite strain passed to the update.
    #[error("non-finite strain [{}, {}, {}]", .0[0], .0[1], .0[2])]
    NonFiniteStrain([f64; 3]),
    /// A local iteration other than the return mapping (e.g. creep in series with cracking)
    /// did not converge for this strain increment: like a return mapping that did not
    /// converge, the caller cuts the step and retries.
    #[error("local iteration not converged: {0}")]
    LocalNotConverged(String),
    /// Inconsistent material parameters.
    #[error("invalid material parameters: {0}")]
    InvalidParams(String),
}
