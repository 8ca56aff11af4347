//! Linear elastic isotropic material in plane stress.

/// Plane-stress elasticity matrix D [Pa] for modulus `e` [Pa] and Poisson ratio `nu`,
/// Voigt order (xx, yy, xy) with engineering shear strain.
pub fn plane_stress_d(e: f64, nu: f64) -> [[f64; 3]; 3] {
    let c = e / (1.0 - nu * nu);
    [
        [c, c * nu, 0.0],
        [c * nu, c, 0.0],
        [0.0, 0.0, c * (1.0 - nu) / 2.0],
    ]
}

/// σ = D ε for a 3×3 matrix.
pub fn mul3(d: &[[f64; 3]; 3], e: &[f64; 3]) -> [f64; 3] {
    [
        d[0][0] * e[0] + d[0][1] * e[1] + d[0][2] * e[2],
        d[1][0] * e[0] + d[1][1] * e[1] + d[1][2] * e[2],
        d[2][0] * e[0] + d[2][1] * e[1] + d[2][2] * e[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniaxial stress σx = E εx with εy = −ν εx (plane stress).
    #[test]
    fn uniaxial_stress_state() {
        let (e, nu) = (30e9, 0.2);
        let d = plane_stress_d(e, nu);
        let s = mul3(&d, &[1e-4, -nu * 1e-4, 0.0]);
        assert!((s[0] - e * 1e-4).abs() < 1e-6 * e * 1e-4);
        assert!(s[1].abs() < 1e-9 * e * 1e-4);
        let g = mul3(&d, &[0.0, 0.0, 1e-4]);
        assert!((g[2] - e / (2.0 * (1.0 + nu)) * 1e-4).abs() < 1e-9 * e * 1e-4);
    }
}
