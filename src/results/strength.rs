//! Stresses of concrete modelled as elastic checked against its strength (issue 38 item 4).
//!
//! An `elastic` material given `fcm`/`ftm`/`class`, and every `elastic_creep` material (its
//! f_cm is given), carries a [`Strength`] its law does not model: it neither cracks nor
//! crushes. After each converged increment the watch reads the committed Gauss-point
//! stresses of the regions of such materials, and the contact stresses of the joints beside
//! them, and keeps the first and the worst point where
//!
//! - the minor principal stress σ2 is more compressive than −f_cm ("compression"),
//! - a joint's contact stress exceeds the smallest f_cm of the elements on its two faces
//!   ("joint contact"),
//! - the major principal stress σ1 exceeds f_tm ("tension").
//!
//! The uniaxial strengths are the check, not a failure surface: biaxial compression is up
//! to ≈ 1.16 f_cm stronger, compression with lateral tension weaker (docs/running.md,
//! "Concrete past its strength"). Compression past f_cm makes any later failure load an
//! upper bound (the concrete would have crushed first); tension past f_tm means the
//! concrete would have cracked (stiffness and load paths beyond are those of uncracked
//! concrete).

use crate::analysis::steps::Snapshot;
use crate::model::{Model, Strength};
use crate::results::fields::principal;
use serde::{Deserialize, Serialize};

/// Which strength was passed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Exceeded {
    /// σ2 < −f_cm in a continuum point.
    Compression,
    /// A joint contact stress above f_cm.
    JointContact,
    /// σ1 > f_tm in a continuum point.
    Tension,
}

impl Exceeded {
    /// Words for messages.
    pub fn words(self) -> &'static str {
        match self {
            Exceeded::Compression => "compression",
            Exceeded::JointContact => "joint contact stress",
            Exceeded::Tension => "tension",
        }
    }

    /// The strength's symbol.
    fn limit_name(self) -> &'static str {
        match self {
            Exceeded::Compression | Exceeded::JointContact => "fcm",
            Exceeded::Tension => "ftm",
        }
    }

    /// True where the failure loads of the run become upper bounds (the concrete would have
    /// crushed).
    pub fn bounds_the_capacity(self) -> bool {
        !matches!(self, Exceeded::Tension)
    }
}

/// One point past the strength.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Hit {
    /// Index of the converged increment among those watched.
    pub k: usize,
    /// Step index and increment (1-based).
    pub step: usize,
    pub increment: usize,
    /// Stress magnitude [Pa] and the strength it passed [Pa].
    pub value: f64,
    pub limit: f64,
    /// Where: "joint J4" or "element 97 (x = 2.30 m, y = 0.50 m)", with the material.
    pub place: String,
}

/// The first and the worst (largest value/limit) hit of one kind.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Record {
    pub first: Hit,
    pub worst: Hit,
}

/// A strength passed, as summary.json lists it (`strength_exceeded`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StrengthFinding {
    /// What was passed.
    pub kind: Exceeded,
    /// The strength [Pa] at the first point.
    pub limit_pa: f64,
    /// Stress magnitude [Pa] where it was first passed.
    pub first_pa: f64,
    /// Where it was first passed.
    pub first_at: String,
    /// Step name and increment (1-based) where it was first passed.
    pub step: String,
    /// Increment within the step (1-based).
    pub increment: usize,
    /// Load case of the run's load measure and its factor there (runs to failure), if any.
    pub load_case: Option<String>,
    /// The load measure's value where the strength was first passed.
    pub at_factor: Option<f64>,
    /// Largest stress magnitude over the run [Pa], with its strength [Pa] and place.
    pub worst_pa: f64,
    /// The strength at the worst point [Pa].
    pub worst_limit_pa: f64,
    /// Where the worst point is.
    pub worst_at: String,
    /// The finding in one sentence (also in summary.json `warnings`).
    pub text: String,
}

/// Watches converged increments for stresses past the strength of elastic concrete.
#[derive(Debug, Default)]
pub struct StrengthWatch {
    /// Strength of each region's material (None: not checked); empty until the first
    /// increment.
    regions: Vec<Option<Strength>>,
    /// f_cm [Pa] each interface element is checked against (the smallest of the checked
    /// materials of the elements on its faces).
    interfaces: Vec<Option<f64>>,
    ready: bool,
    records: Vec<(Exceeded, Record)>,
}

impl StrengthWatch {
    /// A watch with nothing seen.
    pub fn new() -> Self {
        Self::default()
    }

    /// Set up from the model: which regions and joints are checked.
    fn prepare(&mut self, model: &Model) {
        self.ready = true;
        self.regions = model
            .regions
            .iter()
            .map(|r| model.materials[r.material].strength)
            .collect();
        if self.regions.iter().all(Option::is_none) {
            return;
        }
        let mut by_node: Vec<Vec<usize>> = vec![Vec::new(); model.nodes.len()];
        for (e, el) in model.elements.iter().enumerate() {
            for &n in &el.nodes {
                by_node[n].push(e);
            }
        }
        // The element owning a face: the one holding every node of it.
        let owner = |face: &[usize]| {
            by_node[face[0]]
                .iter()
                .copied()
                .find(|&e| face.iter().all(|n| model.elements[e].nodes.contains(n)))
        };
        self.interfaces = model
            .interfaces
            .iter()
            .map(|i| {
                let (a, b) = i.nodes.split_at(i.n_a);
                [owner(a), owner(b)]
                    .into_iter()
                    .flatten()
                    .filter_map(|e| self.regions[model.elements[e].region].map(|s| s.fcm))
                    .reduce(f64::min)
            })
            .collect();
    }

    /// Check converged increment number `k` (counted over the run's converged increments).
    pub fn increment(&mut self, snap: &Snapshot, k: usize) {
        let sys = snap.system;
        let model = sys.model;
        if !self.ready {
            self.prepare(model);
        }
        if self.regions.iter().all(Option::is_none) {
            return;
        }
        // The worst point of each kind in this increment: (ratio, value, limit, place).
        let mut worst: [Option<(f64, f64, f64, usize)>; 3] = [None; 3];
        let mut note = |slot: usize, value: f64, limit: f64, at: usize| {
            let ratio = value / limit;
            if ratio > 1.0 && worst[slot].is_none_or(|w| ratio > w.0) {
                worst[slot] = Some((ratio, value, limit, at));
            }
        };
        for (e, el) in model.elements.iter().enumerate() {
            let Some(s) = self.regions[el.region] else {
                continue;
            };
            for g in sys.element_gauss(e) {
                let (s1, s2) = principal(&g.stress);
                note(0, -s2, s.fcm, e);
                note(2, s1, s.ftm, e);
            }
        }
        for (i, fcm) in self.interfaces.iter().enumerate() {
            let Some(fcm) = *fcm else { continue };
            for st in sys.joint_points(i) {
                note(1, st.normal_stress(), fcm, i);
            }
        }
        let kinds = [
            Exceeded::Compression,
            Exceeded::JointContact,
            Exceeded::Tension,
        ];
        for (kind, w) in kinds.into_iter().zip(worst) {
            let Some((ratio, value, limit, at)) = w else {
                continue;
            };
            let place = match kind {
                Exceeded::JointContact => {
                    format!("joint {}", model.joints[model.interfaces[at].joint].name)
                }
                _ => element_place(model, at),
            };
            let hit = Hit {
                k,
                step: snap.step,
                increment: snap.increment,
                value,
                limit,
                place,
            };
            match self.records.iter_mut().find(|(c, _)| *c == kind) {
                Some((_, r)) => {
                    if ratio > r.worst.value / r.worst.limit {
                        r.worst = hit;
                    }
                }
                None => self.records.push((
                    kind,
                    Record {
                        first: hit.clone(),
                        worst: hit,
                    },
                )),
            }
        }
    }

    /// The first hit of each kind that bounds the capacity (compression, joint contact).
    pub(crate) fn first_crushing(&self) -> Option<(Exceeded, &Hit)> {
        self.records
            .iter()
            .filter(|(c, _)| c.bounds_the_capacity())
            .map(|(c, r)| (*c, &r.first))
            .min_by_key(|(_, h)| h.k)
    }

    /// The strengths passed, in the order first met; `measure`: the name of the run's load
    /// measure and its value at each watched increment (runs to failure), for the text.
    pub fn findings(&self, model: &Model, measure: Option<(&str, &[f64])>) -> Vec<StrengthFinding> {
        let mut records: Vec<&(Exceeded, Record)> = self.records.iter().collect();
        records.sort_by_key(|(_, r)| r.first.k);
        records
            .into_iter()
            .map(|(kind, r)| {
                let (f, w) = (&r.first, &r.worst);
                let at = measure.and_then(|(name, v)| v.get(f.k).map(|&x| (name.to_string(), x)));
                let when = match &at {
                    Some((name, x)) => format!(
                        "{name} = {} (step '{}', increment {})",
                        fmt_measure(name, *x),
                        model.steps[f.step].name,
                        f.increment
                    ),
                    None => format!("step '{}', increment {}", model.steps[f.step].name, f.increment),
                };
                let consequence = if kind.bounds_the_capacity() {
                    "the material is elastic and cannot crush: loads reached beyond this point, a failure load included, are upper bounds"
                } else {
                    "the material is elastic and cannot crack: stiffness and load paths beyond this point are those of uncracked concrete"
                };
                let text = format!(
                    "concrete past its strength: {} {:.1} MPa > {} {:.1} MPa at {} from {when} (worst {:.1} MPa against {:.1} MPa at {}, step '{}', increment {}); {consequence}",
                    kind.words(),
                    f.value / 1e6,
                    kind.limit_name(),
                    f.limit / 1e6,
                    f.place,
                    w.value / 1e6,
                    w.limit / 1e6,
                    w.place,
                    model.steps[w.step].name,
                    w.increment
                );
                StrengthFinding {
                    kind: *kind,
                    limit_pa: f.limit,
                    first_pa: f.value,
                    first_at: f.place.clone(),
                    step: model.steps[f.step].name.clone(),
                    increment: f.increment,
                    load_case: at.as_ref().map(|(n, _)| n.clone()),
                    at_factor: at.map(|(_, x)| x),
                    worst_pa: w.value,
                    worst_limit_pa: w.limit,
                    worst_at: w.place.clone(),
                    text,
                }
            })
            .collect()
    }
}

/// "element 97 (region 'webs', x = 2.30 m, y = 0.50 m)": 1-based number, centroid of the
/// element's nodes.
/// Where element `e` is, for messages: its number, region and centroid.
pub(crate) fn element_place(model: &Model, e: usize) -> String {
    let el = &model.elements[e];
    let n = el.nodes.len() as f64;
    let (x, y) = el.nodes.iter().fold((0.0, 0.0), |(x, y), &i| {
        (x + model.nodes[i][0] / n, y + model.nodes[i][1] / n)
    });
    format!(
        "element {} (region '{}', x = {x:.2} m, y = {y:.2} m)",
        e + 1,
        model.regions[el.region].name
    )
}

/// The load measure as the verdict prints it: a factor to four decimals, a control force
/// in kN.
pub(crate) fn fmt_measure(name: &str, x: f64) -> String {
    if name == crate::results::ultimate::CONTROL_FORCE {
        format!("{:.4} kN", x / 1e3)
    } else {
        format!("{x:.4}")
    }
}
