//! Helpers of the Newton iterations shared by the step drivers (`steps`, `path`): norms and
//! the residual-history tests. Pure functions of their arguments; this module calls no
//! driver, so the drivers can share it without calling each other for it.

/// Euclidean norm of `v`.
pub(super) fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Newton cycles: six iterations made and the relative residual not halved over the last
/// three (crack points alternating between loading and unloading); the drivers then hold the
/// crack branches for the rest of the increment.
pub(super) fn cycling(history: &[f64]) -> bool {
    let n = history.len();
    n >= 7 && history[n - 1] >= 0.5 * history[n - 4]
}

/// Correction scale from the residual history: 1, or ½, ¼, … (at least 1/16) while the
/// relative residual has not fallen by 10 % over the last two iterations.
pub(super) fn damping(history: &[f64]) -> f64 {
    let n = history.len();
    let mut k = 0;
    let mut i = n;
    while i >= 3 && history[i - 1] >= 0.9 * history[i - 3] && k < 4 {
        k += 1;
        i -= 1;
    }
    0.5_f64.powi(k)
}
