//! Degree-of-freedom map: two dofs per node (ux, uy), global dof = 2·node + direction;
//! constrained dofs are removed from the equation numbering.

/// Marker for a constrained dof in the equation map.
pub const CONSTRAINED: usize = usize::MAX;

/// Equation numbering of the free dofs.
#[derive(Debug, Clone)]
pub struct DofMap {
    /// Equation number of each global dof, or [`CONSTRAINED`].
    pub eq: Vec<usize>,
    /// Number of equations (free dofs).
    pub n_eq: usize,
    /// Constrained dofs with their prescribed displacement [m].
    pub prescribed: Vec<(usize, f64)>,
}

impl DofMap {
    /// Number the free dofs of `n_nodes` nodes in node order, given the constrained dofs.
    /// A dof constrained twice keeps the last prescribed value.
    pub fn new(n_nodes: usize, constrained: &[(usize, f64)]) -> Self {
        let mut eq = vec![0usize; 2 * n_nodes];
        let mut value = vec![None; 2 * n_nodes];
        for &(d, v) in constrained {
            value[d] = Some(v);
        }
        let mut n_eq = 0;
        let mut prescribed = Vec::new();
        for d in 0..2 * n_nodes {
            match value[d] {
                Some(v) => {
                    eq[d] = CONSTRAINED;
                    prescribed.push((d, v));
                }
                None => {
                    eq[d] = n_eq;
                    n_eq += 1;
                }
            }
        }
        Self {
            eq,
            n_eq,
            prescribed,
        }
    }
}
