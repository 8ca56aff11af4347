//! Gauss–Legendre and Gauss–Lobatto rules on [−1, 1] and their tensor products on the square.

/// A 1-D rule: points and weights on [−1, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct Rule1 {
    /// Abscissae in [−1, 1].
    pub points: Vec<f64>,
    /// Weights (sum 2).
    pub weights: Vec<f64>,
}

/// Gauss–Legendre rule with `n` points (1 ≤ n ≤ 4); exact for polynomials of degree 2n − 1.
pub fn gauss(n: usize) -> Rule1 {
    let (p, w): (Vec<f64>, Vec<f64>) = match n {
        1 => (vec![0.0], vec![2.0]),
        2 => {
            let a = 1.0 / 3f64.sqrt();
            (vec![-a, a], vec![1.0, 1.0])
        }
        3 => {
            let a = (0.6f64).sqrt();
            (vec![-a, 0.0, a], vec![5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
        }
        4 => {
            let s = (6.0 / 5.0f64).sqrt();
            let a = ((3.0 - 2.0 * s) / 7.0).sqrt();
            let b = ((3.0 + 2.0 * s) / 7.0).sqrt();
            let wa = (18.0 + 30f64.sqrt()) / 36.0;
            let wb = (18.0 - 30f64.sqrt()) / 36.0;
            (vec![-b, -a, a, b], vec![wb, wa, wa, wb])
        }
        _ => panic!("gauss rule with {n} points is not provided (1..=4)"),
    };
    Rule1 {
        points: p,
        weights: w,
    }
}

/// Gauss–Lobatto rule with `n` points (2 or 3): the end points are integration points, which
/// decouples nodal tractions of stiff interface elements (Schellekens & de Borst 1993).
pub fn lobatto(n: usize) -> Rule1 {
    match n {
        2 => Rule1 {
            points: vec![-1.0, 1.0],
            weights: vec![1.0, 1.0],
        },
        3 => Rule1 {
            points: vec![-1.0, 0.0, 1.0],
            weights: vec![1.0 / 3.0, 4.0 / 3.0, 1.0 / 3.0],
        },
        _ => panic!("lobatto rule with {n} points is not provided (2..=3)"),
    }
}

/// A point of a 2-D rule on the square [−1, 1]²: (ξ, η, weight).
pub type Point2 = (f64, f64, f64);

/// Tensor-product Gauss rule with `n × n` points, ordered η-major (row by row).
pub fn gauss_square(n: usize) -> Vec<Point2> {
    let r = gauss(n);
    let mut out = Vec::with_capacity(n * n);
    for (j, eta) in r.points.iter().enumerate() {
        for (i, xi) in r.points.iter().enumerate() {
            out.push((*xi, *eta, r.weights[i] * r.weights[j]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each n-point Gauss rule integrates x^k exactly for k ≤ 2n − 1.
    #[test]
    fn gauss_rules_are_exact_to_their_degree() {
        for n in 1..=4 {
            let r = gauss(n);
            for k in 0..(2 * n) {
                let exact = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k as f64 + 1.0)
                };
                let num: f64 = r
                    .points
                    .iter()
                    .zip(&r.weights)
                    .map(|(x, w)| w * x.powi(k as i32))
                    .sum();
                assert!((num - exact).abs() < 1e-14, "n={n} k={k}");
            }
        }
    }

    /// 3-point Lobatto integrates cubics exactly.
    #[test]
    fn lobatto_3_is_exact_to_degree_3() {
        let r = lobatto(3);
        for k in 0..4 {
            let exact = if k % 2 == 1 {
                0.0
            } else {
                2.0 / (k as f64 + 1.0)
            };
            let num: f64 = r
                .points
                .iter()
                .zip(&r.weights)
                .map(|(x, w)| w * x.powi(k))
                .sum();
            assert!((num - exact).abs() < 1e-14);
        }
    }
}
