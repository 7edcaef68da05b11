//! The segmentation's parameters, derived from the scan's own figures.
//!
//! The thesis says σ_w and σ_c "should be set according to the noise level
//! in the input data" (§2.3.2) and gives no numbers. Here every parameter
//! has a default computed from what [`crate::segment::normals`] measured
//! (point spacing, noise across the surface, normal and intensity noise); a
//! user may fix any of them ([`Overrides`], RON or JSON). The chosen values
//! come back with their reasons ([`Choice`]).

use serde::{Deserialize, Serialize};

use super::normals::ScanFigures;

/// Values a user fixes; `None` (the default) means "derive from the scan".
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Overrides {
    /// Coarse cluster radius, m.
    pub cluster_radius_m: Option<f64>,
    /// σ_w of eq. 2.3 for normals, degrees.
    pub sigma_w_normal_deg: Option<f64>,
    /// σ_w of eq. 2.3 for intensity (intensity in [0, 1]).
    pub sigma_w_intensity: Option<f64>,
    /// σ_c of eq. 2.4 as a multiple of the cluster radius.
    pub sigma_c_over_radius: Option<f64>,
    /// E of eq. 2.5 (≥ 1).
    pub anisotropy: Option<f64>,
    /// T_cut: the threshold both Ncut (eq. 2.1) and NWAcut (eq. 2.6) must
    /// fall below for a split.
    pub t_cut: Option<f64>,
    /// Run the fine segmentation (§2.3.4).
    pub fine: Option<bool>,
    /// Run boundary improvement by local voting (§2.3.4).
    pub boundary_voting: Option<bool>,
    /// Groups with fewer points are dissolved into their neighbours.
    pub min_group_points: Option<usize>,
    /// Random long-range edges per node (§2.3.2).
    pub random_edges: Option<usize>,
    /// Seed for the random edges.
    pub seed: Option<u64>,
    /// Divide intensities by the cosine of the beam's incidence
    /// ([`crate::segment::normals::corrected_intensity`]).
    pub correct_incidence: Option<bool>,
    /// Split layers proud of a plane or set into it from its group
    /// ([`crate::segment::relief`]).
    pub relief: Option<bool>,
    /// The least step such a layer stands off its plane, m.
    pub relief_step_m: Option<f64>,
    /// Make sets of unassigned points that lie together groups of their own
    /// ([`crate::segment::objects`]).
    pub objects: Option<bool>,
}

/// The parameters in force.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Parameters {
    /// Coarse cluster radius: a point joins a cluster whose centroid is
    /// within it (§2.3.2), m.
    pub cluster_radius_m: f64,
    /// Largest angle between a point's normal and its cluster's, degrees.
    pub cluster_normal_deg: f64,
    /// Largest intensity difference between a point and its cluster.
    pub cluster_intensity: f64,
    /// Nodes are joined by an edge when their centroids are this close, m.
    pub edge_radius_m: f64,
    /// Random long-range edges per node.
    pub random_edges: usize,
    /// σ_w for normals (eq. 2.3), degrees.
    pub sigma_w_normal_deg: f64,
    /// σ_w for intensity (eq. 2.3).
    pub sigma_w_intensity: f64,
    /// σ_c (eq. 2.4), m.
    pub sigma_c_m: f64,
    /// E (eq. 2.5).
    pub anisotropy: f64,
    /// T_cut (§2.3.3).
    pub t_cut: f64,
    /// Regions with fewer nodes are not split.
    pub min_region_nodes: usize,
    /// Run boundary improvement by local voting.
    pub boundary_voting: bool,
    /// Run the fine segmentation at half the radius and σ_c.
    pub fine: bool,
    /// Groups with fewer points are dissolved into their neighbours.
    pub min_group_points: usize,
    /// Seed for the random edges.
    pub seed: u64,
    /// Intensities are divided by the cosine of the beam's incidence.
    pub correct_incidence: bool,
    /// One point's intensity noise (σ) as compared: a node of n points
    /// knows its mean to σ/√n, which widens eq. 2.3's σ_w on its edges.
    pub intensity_noise: f64,
    /// Split layers proud of a plane or set into it from its group
    /// ([`crate::segment::relief`]).
    pub relief: bool,
    /// The least step such a layer stands off its plane, m.
    pub relief_step_m: f64,
    /// Make sets of unassigned points that lie together groups of their own
    /// ([`crate::segment::objects`]).
    pub objects: bool,
}

/// The range of σ_w for normals, degrees.
const SIGMA_W_NORMAL_DEG: (f64, f64) = (4.0, 25.0);
/// The exponent of cos incidence the returns must follow, at least, for
/// the intensities to be divided by it: halfway between a scanner that
/// corrects its returns (0) and one that does not (1).
const INCIDENCE_SLOPE: f64 = 0.5;
/// The least σ_w for intensity.
const SIGMA_W_INTENSITY_MIN: f64 = 0.02;

/// One parameter's value and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Choice {
    /// The parameter.
    pub name: String,
    /// Its value.
    pub value: f64,
    /// Why: the figure it came from, or "given".
    pub reason: String,
}

/// A parameter that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("segmentation parameter {name} = {value}: expected {expected}")]
pub struct ParameterError {
    /// The parameter.
    pub name: &'static str,
    /// Its value.
    pub value: f64,
    /// What it should be.
    pub expected: &'static str,
}

/// Records a parameter's value, the given one or the derived one with its
/// reason; returns the value.
fn record(choices: &mut Vec<Choice>, name: String, given: Option<f64>, derived: f64, reason: String) -> f64 {
    let (value, reason) = match given {
        Some(v) => (v, "given".to_string()),
        None => (derived, reason),
    };
    choices.push(Choice { name, value, reason });
    value
}

impl Parameters {
    /// Derives every parameter from `figures`, except those `overrides`
    /// fixes; returns them with their reasons.
    pub fn choose(figures: &ScanFigures, overrides: &Overrides) -> Result<(Parameters, Vec<Choice>), ParameterError> {
        let mut choices = Vec::new();
        let mut pick = |name: &str, given: Option<f64>, derived: f64, reason: String| {
            record(&mut choices, name.into(), given, derived, reason)
        };
        let s = figures.spacing_m;
        let noise = figures.noise_m;
        let radius = pick(
            "cluster_radius_m",
            overrides.cluster_radius_m,
            (4.0 * s).max(12.0 * noise),
            format!(
                "4 × spacing {s:.4} m (at least 12 × noise {noise:.4} m, so that a cluster's mean normal is steady on dense, noisy scans): about 50 points a cluster"
            ),
        );
        let nn = figures.normal_noise_deg;
        let cluster_normal = pick(
            "cluster_normal_deg",
            None,
            (3.5 * nn).clamp(10.0, 30.0),
            format!("3.5 × normal noise {nn:.2}° (a point's normal is within it 99 % of the time), within 10°–30°"),
        );
        let slope = figures.incidence_slope;
        let correct_incidence = pick(
            "correct_incidence",
            overrides.correct_incidence.map(|c| f64::from(u8::from(c))),
            f64::from(u8::from(slope.is_some_and(|k| k >= INCIDENCE_SLOPE))),
            match slope {
                Some(k) => format!(
                    "the returns follow cos incidence with exponent {k:.2} (ln intensity on ln cos between points on one plane; corrected from {INCIDENCE_SLOPE})"
                ),
                None => "no pose, no intensity or too few pairs to measure how returns follow the incidence".into(),
            },
        ) > 0.5;
        let inoise = if correct_incidence {
            figures.corrected_intensity_noise.or(figures.intensity_noise)
        } else {
            figures.intensity_noise
        }
        .unwrap_or(0.0);
        let cluster_intensity = pick(
            "cluster_intensity",
            None,
            (4.0 * inoise).max(0.05),
            format!("4 × intensity noise {inoise:.4}, at least 0.05"),
        );
        let edge_radius = pick(
            "edge_radius_m",
            None,
            2.2 * radius,
            "2.2 × cluster radius: every cluster reaches its ring of neighbours".into(),
        );
        let random_edges = pick(
            "random_edges",
            overrides.random_edges.map(|v| v as f64),
            2.0,
            "2 a node, to a cluster within twice the edge radius (§2.3.2's long-range edges)".into(),
        );
        // σ_w is set from the graph's own edges (see `adapt_sigma_w`); these
        // are the values a graph without local edges keeps.
        let sigma_w_normal = overrides.sigma_w_normal_deg.unwrap_or(SIGMA_W_NORMAL_DEG.0);
        let sigma_w_intensity = overrides.sigma_w_intensity.unwrap_or(SIGMA_W_INTENSITY_MIN);
        let sigma_c_ratio = overrides.sigma_c_over_radius.unwrap_or(1.5);
        let sigma_c = pick(
            "sigma_c_m",
            overrides.sigma_c_over_radius.map(|r| r * radius),
            sigma_c_ratio * radius,
            "1.5 × cluster radius: neighbouring clusters are near, the next ring far".into(),
        );
        let anisotropy = pick(
            "anisotropy",
            overrides.anisotropy,
            if noise > 0.0 {
                (s / (2.0 * noise)).clamp(1.0, 16.0)
            } else {
                16.0
            },
            format!(
                "spacing {s:.4} m / (2 × noise {noise:.4} m), within 1–16: a depth step of twice the noise weighs as one spacing along the surface"
            ),
        );
        let t_cut = pick(
            "t_cut",
            overrides.t_cut,
            0.2,
            "the thesis gives none; 0.2 separates the box room's faces and keeps its planes whole".into(),
        );
        let min_group_points = pick(
            "min_group_points",
            overrides.min_group_points.map(|v| v as f64),
            30.0,
            "30 points: smaller groups are clutter and edge pixels".into(),
        );
        let relief = pick(
            "relief",
            overrides.relief.map(|r| f64::from(u8::from(r))),
            1.0,
            "layers proud of a plane (posters, boards) are split from its group".into(),
        ) > 0.5;
        let relief_step_m = pick(
            "relief_step_m",
            overrides.relief_step_m,
            2.0 * noise,
            format!(
                "2 × noise {noise:.4} m: a layer's median point stands this far off its plane; cells of about 10 points see it at 5 standard errors or more"
            ),
        );
        let objects = pick(
            "objects",
            overrides.objects.map(|o| f64::from(u8::from(o))),
            1.0,
            "unassigned points within twice their distance to their nearest unassigned neighbour of each other (both ways), at least min_group_points of them, make a group: objects smaller than a cluster".into(),
        ) > 0.5;
        let parameters = Parameters {
            cluster_radius_m: radius,
            cluster_normal_deg: cluster_normal,
            cluster_intensity,
            edge_radius_m: edge_radius,
            random_edges: random_edges as usize,
            sigma_w_normal_deg: sigma_w_normal,
            sigma_w_intensity,
            sigma_c_m: sigma_c,
            anisotropy,
            t_cut,
            min_region_nodes: 4,
            boundary_voting: overrides.boundary_voting.unwrap_or(true),
            fine: overrides.fine.unwrap_or(true),
            min_group_points: min_group_points as usize,
            seed: overrides.seed.unwrap_or(28),
            correct_incidence,
            intensity_noise: inoise,
            relief,
            relief_step_m,
            objects,
        };
        parameters.check()?;
        Ok((parameters, choices))
    }

    /// Refuses values the algorithm cannot use.
    pub fn check(&self) -> Result<(), ParameterError> {
        let positive: [(&'static str, f64); 6] = [
            ("cluster_radius_m", self.cluster_radius_m),
            ("edge_radius_m", self.edge_radius_m),
            ("sigma_w_normal_deg", self.sigma_w_normal_deg),
            ("sigma_w_intensity", self.sigma_w_intensity),
            ("sigma_c_m", self.sigma_c_m),
            ("t_cut", self.t_cut),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(ParameterError {
                    name,
                    value,
                    expected: "a finite number above 0",
                });
            }
        }
        if !(self.relief_step_m.is_finite() && self.relief_step_m >= 0.0) {
            return Err(ParameterError {
                name: "relief_step_m",
                value: self.relief_step_m,
                expected: "a finite number ≥ 0, in metres",
            });
        }
        if !(self.anisotropy.is_finite() && self.anisotropy >= 1.0) {
            return Err(ParameterError {
                name: "anisotropy",
                value: self.anisotropy,
                expected: "a finite number ≥ 1 (eq. 2.5's E)",
            });
        }
        Ok(())
    }

    /// Sets σ_w (eq. 2.3) from the graph's clusters, unless given: 4 × the
    /// median normal difference between neighbouring clusters (within
    /// 4°–25°), and 4 × their median intensity difference (at least 0.02).
    /// Most edges lie within a surface, so the medians are the clusters' own
    /// noise; a cluster pair at the 99th percentile of that noise keeps
    /// S ≈ 0.8, a crease of 30° or more gets S below 0.01.
    pub fn adapt_sigma_w(
        &mut self,
        median_normal_rad: f64,
        median_intensity: f64,
        overrides: &Overrides,
        stage: &str,
        choices: &mut Vec<Choice>,
    ) {
        let mut set = |name: &str, given: Option<f64>, derived: f64, reason: String| {
            record(choices, format!("{stage}_{name}"), given, derived, reason)
        };
        let m = median_normal_rad.to_degrees();
        self.sigma_w_normal_deg = set(
            "sigma_w_normal_deg",
            overrides.sigma_w_normal_deg,
            (4.0 * m).clamp(SIGMA_W_NORMAL_DEG.0, SIGMA_W_NORMAL_DEG.1),
            format!("4 × the median normal difference {m:.2}° between neighbouring {stage} clusters, within 4°–25°"),
        );
        self.sigma_w_intensity = set(
            "sigma_w_intensity",
            overrides.sigma_w_intensity,
            (4.0 * median_intensity).max(SIGMA_W_INTENSITY_MIN),
            format!(
                "4 × the median intensity difference {median_intensity:.4} between neighbouring {stage} clusters, at least 0.02"
            ),
        );
    }

    /// The fine stage's parameters (§2.3.4): half the radius and σ_c.
    pub fn fine_scale(&self) -> Parameters {
        Parameters {
            cluster_radius_m: self.cluster_radius_m / 2.0,
            edge_radius_m: self.edge_radius_m / 2.0,
            sigma_c_m: self.sigma_c_m / 2.0,
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figures(slope: Option<f64>) -> ScanFigures {
        ScanFigures {
            spacing_m: 0.03,
            noise_m: 0.003,
            normal_noise_deg: 2.0,
            intensity_noise: Some(0.01),
            corrected_intensity_noise: Some(0.02),
            incidence_slope: slope,
            points: 1000,
        }
    }

    fn correction(parameters: &[Choice]) -> &Choice {
        parameters.iter().find(|c| c.name == "correct_incidence").unwrap()
    }

    #[test]
    fn the_incidence_correction_follows_the_measured_slope_unless_given() {
        let none = Overrides::default();
        let (p, c) = Parameters::choose(&figures(Some(0.9)), &none).unwrap();
        assert!(p.correct_incidence);
        assert!(correction(&c).reason.contains("exponent 0.90"), "{:?}", correction(&c));
        // The corrected intensity's noise sets the cluster's limit (4 × 0.02).
        assert!((p.cluster_intensity - 0.08).abs() < 1e-12);
        assert!((p.intensity_noise - 0.02).abs() < 1e-12);
        let (p, _) = Parameters::choose(&figures(Some(0.1)), &none).unwrap();
        assert!(!p.correct_incidence);
        assert!((p.intensity_noise - 0.01).abs() < 1e-12);
        let (p, c) = Parameters::choose(&figures(None), &none).unwrap();
        assert!(!p.correct_incidence);
        assert!(correction(&c).reason.contains("no pose"));
        // A user's word wins, both ways, and is read from RON.
        let given: Overrides = ron::from_str("(correct_incidence: Some(false))").unwrap();
        let (p, c) = Parameters::choose(&figures(Some(0.9)), &given).unwrap();
        assert!(!p.correct_incidence);
        assert_eq!(correction(&c).reason, "given");
        let given = Overrides {
            correct_incidence: Some(true),
            ..Overrides::default()
        };
        assert!(Parameters::choose(&figures(None), &given).unwrap().0.correct_incidence);
    }
}
