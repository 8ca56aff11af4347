//! Thermal load cases in the engine: the imposed strains of every continuum Gauss point,
//! embedded bar point and external tendon span at unit factor (computed once), and their
//! sum at the current load-case factors, which the element responses subtract from the
//! total strains (docs/theory.md, "Thermal actions"). Not material state: the strains follow
//! from the factors alone, so a cut or a restart simply sets them again.

use crate::elements::continuum::rule_points;
use crate::elements::tendon::ExternalTendon;
use crate::model::ElementKind;
use crate::model::Model;
use crate::model::ThermalAction;

/// Unit-factor imposed strains of one thermal load case.
#[derive(Debug, Clone)]
struct UnitCase {
    /// Load case index.
    case: usize,
    /// α ΔT(y) at each continuum Gauss point (state order) [-].
    points: Vec<f64>,
    /// α_s ΔT(y) at each bar point (in `System::bar_gps` order) [-].
    bars: Vec<f64>,
    /// α_p ΔT of each span of each external tendon [-].
    tendons: Vec<Vec<f64>>,
}

/// The imposed strains of the thermal load cases at the current factors.
#[derive(Debug, Clone, Default)]
pub struct Thermal {
    cases: Vec<UnitCase>,
    /// Imposed normal strain θ of each continuum Gauss point [-] (empty: no thermal case).
    pub points: Vec<f64>,
    /// Thermal strain of each bar point, `System::bar_gps` order [-] (empty: none).
    pub bars: Vec<f64>,
    /// Thermal strain of each span of each external tendon [-].
    pub tendons: Vec<Vec<f64>>,
}

/// Global height y [m] of the point at natural coordinates (ξ, η) of an element.
fn height(kind: ElementKind, coords: &[[f64; 2]], xi: f64, eta: f64) -> f64 {
    let s = kind.eval(xi, eta);
    coords
        .iter()
        .enumerate()
        .map(|(a, c)| s.n_val[a] * c[1])
        .sum()
}

impl Thermal {
    /// The unit strains of the model's thermal load cases; `bar_gps` lists the bar points
    /// (bar, point) in the order of the bar state arrays.
    pub fn new(model: &Model, bar_gps: &[(usize, usize)]) -> Self {
        let mut cases = Vec::new();
        for (c, lc) in model.load_cases.iter().enumerate() {
            let Some(th) = &lc.thermal else {
                continue;
            };
            cases.push(unit_case(model, bar_gps, c, th));
        }
        Self {
            cases,
            ..Default::default()
        }
    }

    /// True if the model has a thermal load case.
    pub fn is_active(&self) -> bool {
        !self.cases.is_empty()
    }

    /// A copy with the strains of the load-case `factors`.
    pub(super) fn at(&self, factors: &[f64]) -> Self {
        let mut t = self.clone();
        t.set(factors);
        t
    }

    /// Set the current strains for the load-case `factors`.
    fn set(&mut self, factors: &[f64]) {
        let Some(first) = self.cases.first() else {
            return;
        };
        let (np, nb) = (first.points.len(), first.bars.len());
        self.points = vec![0.0; np];
        self.bars = vec![0.0; nb];
        self.tendons = first.tendons.iter().map(|t| vec![0.0; t.len()]).collect();
        for uc in &self.cases {
            let l = factors.get(uc.case).copied().unwrap_or(0.0);
            if l == 0.0 {
                continue;
            }
            self.points
                .iter_mut()
                .zip(&uc.points)
                .for_each(|(a, b)| *a += l * b);
            self.bars
                .iter_mut()
                .zip(&uc.bars)
                .for_each(|(a, b)| *a += l * b);
            for (a, b) in self.tendons.iter_mut().zip(&uc.tendons) {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += l * y);
            }
        }
    }
}

/// The unit strains of thermal load case `c` with field `th`.
fn unit_case(model: &Model, bar_gps: &[(usize, usize)], c: usize, th: &ThermalAction) -> UnitCase {
    let mut points = Vec::new();
    for e in &model.elements {
        let coords = model.element_coords(e);
        let alpha = th.region_alpha.get(e.region).copied().unwrap_or(0.0);
        for p in rule_points(e.kind, e.integration) {
            points.push(alpha * th.temperature(height(e.kind, &coords, p.0, p.1)));
        }
    }
    let bars = bar_gps
        .iter()
        .map(|&(b, p)| {
            let y = model.bars[b].points[p].point.x[1];
            th.bar_alpha.get(b).copied().unwrap_or(0.0) * th.temperature(y)
        })
        .collect();
    let tendons = model
        .tendons
        .iter()
        .enumerate()
        .map(|(t, data)| {
            let alpha = th.tendon_alpha.get(t).copied().unwrap_or(0.0);
            data.nodes
                .windows(2)
                .map(|w| alpha * th.span_temperature(model.nodes[w[0]], model.nodes[w[1]]))
                .collect()
        })
        .collect();
    UnitCase {
        case: c,
        points,
        bars,
        tendons,
    }
}

impl Thermal {
    /// Impose the thermal strains of the load-case `factors` (the factors an increment is
    /// solved for): continuum points and bar points through the assembly (which reads
    /// them from here), the external tendons `tendons` (`System::tendons`) through their
    /// span strains. Nothing without thermal load cases.
    pub fn impose(&mut self, factors: &[f64], tendons: &mut [Option<ExternalTendon>]) {
        if !self.is_active() {
            return;
        }
        self.set(factors);
        for (t, el) in tendons.iter_mut().enumerate() {
            if let (Some(el), Some(e)) = (el.as_mut(), self.tendons.get(t)) {
                el.set_thermal_strains(e);
            }
        }
    }
}
