//! The sun-track fit: the model, Levenberg–Marquardt, rejection,
//! covariance and verdict (see the module's documentation).

use chrono::{DateTime, Utc};
use nalgebra::{DMatrix, DVector};

use crate::pose::{HeadPose, Mount, Pinhole};
use crate::quality::Verdict;
use crate::sun::{Observer, sun_position};

/// One sun shot: when it was taken and where the disc's centroid is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunSighting {
    /// When the shot was taken (UTC).
    pub time: DateTime<Utc>,
    /// The disc's centroid, pixels (pixel centres at half-integers), at
    /// the camera's configured resolution.
    pub centroid_px: (f64, f64),
}

/// A fixed camera: its lens, its mount and the head pose it is held at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyCameraModel {
    /// The lens (projection, focal length, principal point, radial terms).
    pub camera: Pinhole,
    /// The mount calibration: the orientation.
    pub mount: Mount,
    /// The head's (fixed) pose.
    pub head: HeadPose,
}

impl SkyCameraModel {
    /// The pixel a world direction (x east, y north, z up) is imaged at.
    pub fn pixel(&self, world: [f64; 3]) -> Option<(f64, f64)> {
        self.camera.project(self.mount.to_camera(self.head, world))
    }

    /// The unit world direction seen at pixel `(u, v)`.
    pub fn ray(&self, u: f64, v: f64) -> Option<[f64; 3]> {
        self.camera.unproject(u, v).map(|d| self.mount.to_world(self.head, d))
    }

    /// The camera's axes (right, down, forward) in the world frame.
    fn axes(&self) -> [[f64; 3]; 3] {
        let o = self.mount.at(self.head);
        [
            o.to_world([1.0, 0.0, 0.0]),
            o.to_world([0.0, 1.0, 0.0]),
            o.to_world([0.0, 0.0, 1.0]),
        ]
    }

    /// The angle, degrees, of the rotation between this camera's
    /// orientation and `other`'s (zero when they look the same way with
    /// the same roll about the axis).
    pub fn orientation_error_deg(&self, other: &SkyCameraModel) -> f64 {
        let (a, b) = (self.axes(), other.axes());
        let trace: f64 = (0..3).map(|k| dot(a[k], b[k])).sum();
        ((trace - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
    }
}

/// The RMS and largest angle, degrees, between the world rays two models
/// give the same pixel, over a grid of `step`-pixel spacing across a
/// `width` × `height` image, at the pixels `truth` sees within
/// `max_off_axis_deg` of its axis: the direction error over the field.
pub fn direction_error_deg(
    truth: &SkyCameraModel,
    model: &SkyCameraModel,
    (width, height): (usize, usize),
    step: usize,
    max_off_axis_deg: f64,
) -> (f64, f64) {
    let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0usize);
    let cos_max = max_off_axis_deg.to_radians().cos();
    for y in (0..height).step_by(step.max(1)) {
        for x in (0..width).step_by(step.max(1)) {
            let (u, v) = (x as f64 + 0.5, y as f64 + 0.5);
            let Some(d) = truth.camera.unproject(u, v) else {
                continue;
            };
            if d[2] < cos_max {
                continue;
            }
            let a = truth.mount.to_world(truth.head, d);
            let e = match model.ray(u, v) {
                Some(b) => angle_deg(a, b),
                None => 180.0,
            };
            sum += e * e;
            max = max.max(e);
            n += 1;
        }
    }
    if n == 0 {
        return (0.0, 0.0);
    }
    ((sum / n as f64).sqrt(), max)
}

/// What the fit frees, and the thresholds of its verdict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CalibrationOptions {
    /// Fit `k2` too (else it is held at the nominal value).
    pub fit_k2: bool,
    /// Fit the principal point too (else it is held): see the module's
    /// documentation for why one day barely separates it from a tilt.
    pub fit_principal_point: bool,
    /// Fewest usable sun shots: fewer fail without a fit.
    pub min_shots: usize,
    /// The track's span (largest angle between two shots' suns), degrees:
    /// shorter is `poor`.
    pub poor_track_deg: f64,
    /// Shorter than this fails.
    pub failed_track_deg: f64,
    /// RMS residual, degrees: more is `poor`.
    pub poor_residual_deg: f64,
    /// More than this fails.
    pub failed_residual_deg: f64,
    /// The largest σ of the three orientation angles, degrees: more is `poor`.
    pub poor_orientation_sigma_deg: f64,
    /// More than this fails.
    pub failed_orientation_sigma_deg: f64,
    /// The largest |correlation| between two free parameters: more is
    /// `poor` (a day that cannot tell them apart).
    pub poor_correlation: f64,
    /// More than this fails: ill-conditioned.
    pub failed_correlation: f64,
    /// The smallest residual, pixels, at which a shot may be rejected as
    /// an outlier (clouds, flare), whatever the spread of the others.
    pub reject_floor_px: f64,
    /// The fraction of shots rejected: more is `poor`; more than twice
    /// this fails.
    pub poor_rejected_fraction: f64,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        CalibrationOptions {
            fit_k2: false,
            fit_principal_point: false,
            min_shots: 8,
            poor_track_deg: 30.0,
            failed_track_deg: 5.0,
            poor_residual_deg: 0.1,
            failed_residual_deg: 0.5,
            poor_orientation_sigma_deg: 0.05,
            failed_orientation_sigma_deg: 0.5,
            poor_correlation: 0.999,
            failed_correlation: 0.99999,
            reject_floor_px: 0.5,
            poor_rejected_fraction: 0.25,
        }
    }
}

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct FitParameter {
    /// Its name: `pan_zero_azimuth_deg`, `level_roll_deg`,
    /// `level_pitch_deg`, `focal_px`, `k1`, `k2`, `principal_x_px`,
    /// `principal_y_px`.
    pub name: &'static str,
    /// The fitted value, in the name's unit.
    pub value: f64,
    /// Its standard deviation from the covariance, same unit (finite: a
    /// parameter the data do not determine gets a huge σ, never NaN).
    pub sigma: f64,
    /// The nominal (starting) value.
    pub nominal: f64,
}

/// A shot left out of the fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Rejected {
    /// Which shot (its index in the input).
    pub index: usize,
    /// When it was taken.
    pub time: DateTime<Utc>,
    /// Its residual, degrees (0 where none could be computed).
    pub residual_deg: f64,
    /// Why.
    pub reason: String,
}

/// The calibration: the model, its uncertainty, its residuals and its verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyCameraCalibration {
    /// The calibrated camera (the nominal one when no fit could be made).
    pub model: SkyCameraModel,
    /// Whether a fit was made.
    pub fitted: bool,
    /// The free parameters, fitted, with their σ.
    pub parameters: Vec<FitParameter>,
    /// Their correlation matrix, in `parameters`' order.
    pub correlation: Vec<Vec<f64>>,
    /// Sun shots given.
    pub shots: usize,
    /// Shots the final fit used.
    pub used: usize,
    /// Shots left out, and why.
    pub rejected: Vec<Rejected>,
    /// RMS angle between each used shot's measured ray and the sun, degrees.
    pub rms_residual_deg: f64,
    /// The largest such angle, degrees.
    pub max_residual_deg: f64,
    /// RMS residual in pixels (per shot, both axes).
    pub rms_residual_px: f64,
    /// The used track's span: the largest angle between two shots' suns, degrees.
    pub track_span_deg: f64,
    /// The used shots' smallest and largest angle off the camera's axis, degrees.
    pub off_axis_range_deg: (f64, f64),
    /// The strongest correlation between two free parameters: names and value.
    pub strongest_correlation: (&'static str, &'static str, f64),
    /// Levenberg–Marquardt iterations over every stage.
    pub iterations: usize,
    /// Whether the last stage converged.
    pub converged: bool,
    /// The verdict.
    pub verdict: Verdict,
    /// The figures behind a verdict other than `ok` (empty when `ok`).
    pub reasons: Vec<String>,
}

/// Why a calibration could not be attempted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// A centroid is not a finite pixel position.
    #[error("sun shot {index} at {time}: centroid ({u}, {v}) px is not a finite pixel position")]
    Centroid {
        /// Which shot.
        index: usize,
        /// When.
        time: DateTime<Utc>,
        /// Column.
        u: f64,
        /// Row.
        v: f64,
    },
    /// The ephemeris refused a time.
    #[error("solar position of sun shot {index}: {message}")]
    Sun {
        /// Which shot.
        index: usize,
        /// What the ephemeris said.
        message: String,
    },
}

/// Shots whose sun is lower than this, degrees, are refused (night, or
/// a refraction the ephemeris's standard atmosphere cannot be trusted for).
const MIN_SUN_ELEVATION_DEG: f64 = -0.5;
/// A predicted pixel that does not exist (behind the lens): a residual this large.
const NO_PIXEL_RESIDUAL_PX: f64 = 1e4;

/// Which parameters are free, in vector order.
#[derive(Debug, Clone, Copy)]
struct Layout {
    k2: bool,
    principal: bool,
}

impl Layout {
    fn names(&self) -> Vec<&'static str> {
        let mut n = vec![
            "pan_zero_azimuth_deg",
            "level_roll_deg",
            "level_pitch_deg",
            "focal_px",
            "k1",
        ];
        if self.k2 {
            n.push("k2");
        }
        if self.principal {
            n.extend(["principal_x_px", "principal_y_px"]);
        }
        n
    }

    fn len(&self) -> usize {
        5 + usize::from(self.k2) + 2 * usize::from(self.principal)
    }

    /// The parameter vector of `m` (angles in radians).
    fn vector(&self, m: &SkyCameraModel) -> DVector<f64> {
        let mut p = vec![
            m.mount.pan_zero_azimuth_rad,
            m.mount.roll_rad,
            m.mount.pitch_rad,
            m.camera.focal_px,
            m.camera.k1,
        ];
        if self.k2 {
            p.push(m.camera.k2);
        }
        if self.principal {
            p.extend([m.camera.principal_px.0, m.camera.principal_px.1]);
        }
        DVector::from_vec(p)
    }

    /// `base` with the free parameters set from `p`.
    fn model(&self, base: &SkyCameraModel, p: &DVector<f64>) -> SkyCameraModel {
        let mut m = *base;
        m.mount.pan_zero_azimuth_rad = p[0];
        m.mount.roll_rad = p[1];
        m.mount.pitch_rad = p[2];
        m.camera.focal_px = p[3];
        m.camera.k1 = p[4];
        let mut i = 5;
        if self.k2 {
            m.camera.k2 = p[i];
            i += 1;
        }
        if self.principal {
            m.camera.principal_px = (p[i], p[i + 1]);
        }
        m
    }

    /// Finite-difference steps, per parameter.
    fn steps(&self, p: &DVector<f64>) -> Vec<f64> {
        (0..self.len())
            .map(|i| match i {
                0..=2 => 1e-7,
                3 => 1e-6 * p[3].abs().max(1.0),
                4 => 1e-7,
                5 if self.k2 => 1e-7,
                _ => 1e-5,
            })
            .collect()
    }

    /// A parameter's value in its report unit.
    fn reported(&self, i: usize, x: f64) -> f64 {
        if i < 3 { x.to_degrees() } else { x }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    dot(c, c).sqrt().atan2(dot(a, b)).to_degrees()
}

/// Pixel residuals (predicted − measured, u then v per shot) of `m`.
fn residuals(m: &SkyCameraModel, suns: &[[f64; 3]], pixels: &[(f64, f64)]) -> DVector<f64> {
    let mut r = DVector::zeros(2 * suns.len());
    for (i, (s, (u, v))) in suns.iter().zip(pixels).enumerate() {
        match m.pixel(*s) {
            Some((pu, pv)) if pu.is_finite() && pv.is_finite() => {
                r[2 * i] = pu - u;
                r[2 * i + 1] = pv - v;
            }
            _ => {
                r[2 * i] = NO_PIXEL_RESIDUAL_PX;
                r[2 * i + 1] = NO_PIXEL_RESIDUAL_PX;
            }
        }
    }
    r
}

/// A shot's residual, degrees: the angle between the ray `m` gives its
/// centroid and the sun (through its pixel residual where the centroid
/// has no ray).
fn residual_deg(m: &SkyCameraModel, sun: [f64; 3], (u, v): (f64, f64)) -> f64 {
    match m.ray(u, v) {
        Some(d) => angle_deg(d, sun),
        None => 180.0,
    }
}

/// Central-difference Jacobian of the weighted residuals.
fn jacobian(
    layout: Layout,
    base: &SkyCameraModel,
    p: &DVector<f64>,
    suns: &[[f64; 3]],
    pixels: &[(f64, f64)],
    weights: &[f64],
) -> DMatrix<f64> {
    let steps = layout.steps(p);
    let mut j = DMatrix::zeros(2 * suns.len(), p.len());
    for (k, h) in steps.iter().enumerate() {
        let (mut a, mut b) = (p.clone(), p.clone());
        a[k] += h;
        b[k] -= h;
        let ra = weighted(residuals(&layout.model(base, &a), suns, pixels), weights);
        let rb = weighted(residuals(&layout.model(base, &b), suns, pixels), weights);
        j.set_column(k, &((ra - rb) / (2.0 * h)));
    }
    j
}

fn weighted(mut r: DVector<f64>, weights: &[f64]) -> DVector<f64> {
    for (i, w) in weights.iter().enumerate() {
        let s = w.sqrt();
        r[2 * i] *= s;
        r[2 * i + 1] *= s;
    }
    r
}

/// The outcome of one Levenberg–Marquardt run.
struct Minimum {
    p: DVector<f64>,
    iterations: usize,
    converged: bool,
}

/// Levenberg–Marquardt (Marquardt's scaling: the damping on the diagonal
/// of JᵀJ) on the weighted pixel residuals, from `p0`.
fn levenberg_marquardt(
    layout: Layout,
    base: &SkyCameraModel,
    p0: DVector<f64>,
    suns: &[[f64; 3]],
    pixels: &[(f64, f64)],
    weights: &[f64],
) -> Minimum {
    let cost_of = |p: &DVector<f64>| weighted(residuals(&layout.model(base, p), suns, pixels), weights).norm_squared();
    let mut p = p0;
    let mut cost = cost_of(&p);
    let mut lambda = 1e-3;
    for iteration in 1..=200 {
        let r = weighted(residuals(&layout.model(base, &p), suns, pixels), weights);
        let j = jacobian(layout, base, &p, suns, pixels, weights);
        let jtj = j.transpose() * &j;
        let g = j.transpose() * r;
        let scale = jtj.diagonal().max().max(1e-300);
        let mut improved = false;
        while lambda < 1e16 {
            let mut a = jtj.clone();
            for k in 0..a.nrows() {
                a[(k, k)] += lambda * jtj[(k, k)].max(1e-12 * scale);
            }
            let Some(chol) = a.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let delta = chol.solve(&(-&g));
            let candidate = &p + &delta;
            let c = cost_of(&candidate);
            if c.is_finite() && c < cost {
                let relative = (cost - c) / cost.max(1e-300);
                let small_step = delta.iter().zip(layout.steps(&p)).all(|(d, h)| d.abs() < 1e-3 * h);
                p = candidate;
                cost = c;
                lambda = (lambda / 10.0).max(1e-12);
                improved = true;
                if relative < 1e-12 || small_step {
                    return Minimum {
                        p,
                        iterations: iteration,
                        converged: true,
                    };
                }
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            // No step lowers the cost: a minimum to the precision of the
            // finite differences.
            return Minimum {
                p,
                iterations: iteration,
                converged: true,
            };
        }
    }
    Minimum {
        p,
        iterations: 200,
        converged: false,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Per-shot residual norms, pixels.
fn norms(r: &DVector<f64>) -> Vec<f64> {
    (0..r.len() / 2).map(|i| r[2 * i].hypot(r[2 * i + 1])).collect()
}

/// Calibrates a fixed sky camera from one day's sun shots: fits the
/// orientation and lens of `nominal` (see the module's documentation) to
/// `sightings` taken at the site `observer` (ΔT `delta_t_s`).
///
/// Never NaN: a calibration with too few usable shots comes back unfitted
/// (`fitted: false`, verdict `failed`, the reason stated); every other
/// case comes back fitted with a verdict and its figures.
pub fn calibrate_sky_camera(
    sightings: &[SunSighting],
    observer: &Observer,
    delta_t_s: Option<f64>,
    nominal: &SkyCameraModel,
    options: &CalibrationOptions,
) -> Result<SkyCameraCalibration, CalibrationError> {
    let layout = Layout {
        k2: options.fit_k2,
        principal: options.fit_principal_point,
    };
    let mut rejected = Vec::new();
    let mut kept: Vec<(usize, [f64; 3], (f64, f64))> = Vec::new();
    for (index, s) in sightings.iter().enumerate() {
        let (u, v) = s.centroid_px;
        if !(u.is_finite() && v.is_finite()) {
            return Err(CalibrationError::Centroid {
                index,
                time: s.time,
                u,
                v,
            });
        }
        let sun = sun_position(s.time, observer, delta_t_s).map_err(|e| CalibrationError::Sun {
            index,
            message: e.to_string(),
        })?;
        let elevation = sun.elevation_rad().to_degrees();
        if elevation < MIN_SUN_ELEVATION_DEG {
            rejected.push(Rejected {
                index,
                time: s.time,
                residual_deg: 0.0,
                reason: format!("the sun is {elevation:.2}° high, below {MIN_SUN_ELEVATION_DEG}°"),
            });
            continue;
        }
        kept.push((index, sun.direction(), s.centroid_px));
    }
    let needed = options.min_shots.max(layout.len() / 2 + 1);
    if kept.len() < needed {
        return Ok(unfitted(
            nominal,
            sightings.len(),
            rejected,
            format!(
                "{} usable sun shots, at least {needed} needed for the {} free parameters",
                kept.len(),
                layout.len()
            ),
        ));
    }

    // Start: the nominal model, its azimuth also tried every 30°.
    let suns: Vec<[f64; 3]> = kept.iter().map(|k| k.1).collect();
    let pixels: Vec<(f64, f64)> = kept.iter().map(|k| k.2).collect();
    let mut p = layout.vector(nominal);
    let robust_cost = |p: &DVector<f64>| {
        let r = residuals(&layout.model(nominal, p), &suns, &pixels);
        median(norms(&r))
    };
    let mut best = robust_cost(&p);
    for k in 1..12 {
        let mut q = p.clone();
        q[0] += f64::from(k) * 30f64.to_radians();
        let c = robust_cost(&q);
        if c < best {
            best = c;
            p = q;
        }
    }

    // Stage 1: Huber weights, rescaled to the residuals' spread each round.
    let mut iterations = 0;
    let mut weights = vec![1.0; suns.len()];
    for _ in 0..6 {
        let m = levenberg_marquardt(layout, nominal, p, &suns, &pixels, &weights);
        iterations += m.iterations;
        p = m.p;
        let e = norms(&residuals(&layout.model(nominal, &p), &suns, &pixels));
        let delta = (2.0 * 1.4826 * median(e.clone())).max(0.05);
        weights = e.iter().map(|&x| if x <= delta { 1.0 } else { delta / x }).collect();
    }

    // Stage 2: reject the outliers, refit the rest unweighted; repeat
    // until none is left out.
    let mut inliers: Vec<usize> = (0..suns.len()).collect();
    let mut converged = false;
    for _ in 0..4 {
        let e = norms(&residuals(&layout.model(nominal, &p), &suns, &pixels));
        let spread = 1.4826 * median(inliers.iter().map(|&i| e[i]).collect());
        let threshold = (5.0 * spread).max(options.reject_floor_px);
        let before = inliers.len();
        let model = layout.model(nominal, &p);
        inliers.retain(|&i| {
            if e[i] <= threshold {
                return true;
            }
            let (index, sun, px) = kept[i];
            rejected.push(Rejected {
                index,
                time: sightings[index].time,
                residual_deg: residual_deg(&model, sun, px),
                reason: format!("residual {:.2} px, over {threshold:.2} px (5 robust deviations)", e[i]),
            });
            false
        });
        if inliers.len() < needed {
            let reason = format!(
                "{} sun shots left after rejecting {} outliers, at least {needed} needed",
                inliers.len(),
                rejected.len()
            );
            return Ok(unfitted(nominal, sightings.len(), rejected, reason));
        }
        let s: Vec<[f64; 3]> = inliers.iter().map(|&i| suns[i]).collect();
        let x: Vec<(f64, f64)> = inliers.iter().map(|&i| pixels[i]).collect();
        let m = levenberg_marquardt(layout, nominal, p.clone(), &s, &x, &vec![1.0; s.len()]);
        iterations += m.iterations;
        p = m.p;
        converged = m.converged;
        if inliers.len() == before {
            break;
        }
    }
    rejected.sort_by_key(|r| r.index);

    let suns: Vec<[f64; 3]> = inliers.iter().map(|&i| suns[i]).collect();
    let pixels: Vec<(f64, f64)> = inliers.iter().map(|&i| pixels[i]).collect();
    let model = layout.model(nominal, &p);
    let ones = vec![1.0; suns.len()];
    let r = residuals(&model, &suns, &pixels);
    let dof = (r.len() as f64 - p.len() as f64).max(1.0);
    let variance = r.norm_squared() / dof;
    let (sigma, correlation) = covariance(&jacobian(layout, nominal, &p, &suns, &pixels, &ones), variance);

    let nominal_p = layout.vector(nominal);
    let names = layout.names();
    let parameters: Vec<FitParameter> = (0..p.len())
        .map(|i| FitParameter {
            name: names[i],
            value: layout.reported(i, p[i]),
            sigma: layout.reported(i, sigma[i]),
            nominal: layout.reported(i, nominal_p[i]),
        })
        .collect();
    let residual_degs: Vec<f64> = suns
        .iter()
        .zip(&pixels)
        .map(|(s, px)| residual_deg(&model, *s, *px))
        .collect();
    let rms_residual_deg = (residual_degs.iter().map(|e| e * e).sum::<f64>() / residual_degs.len() as f64).sqrt();
    let max_residual_deg = residual_degs.iter().copied().fold(0.0, f64::max);
    let rms_residual_px = (r.norm_squared() / suns.len() as f64).sqrt();
    let mut track_span_deg = 0.0f64;
    for (i, a) in suns.iter().enumerate() {
        for b in &suns[i + 1..] {
            track_span_deg = track_span_deg.max(angle_deg(*a, *b));
        }
    }
    let off_axis: Vec<f64> = suns
        .iter()
        .map(|s| {
            let c = model.mount.to_camera(model.head, *s);
            angle_deg(c, [0.0, 0.0, 1.0])
        })
        .collect();
    let off_axis_range_deg = (
        off_axis.iter().copied().fold(f64::INFINITY, f64::min),
        off_axis.iter().copied().fold(0.0, f64::max),
    );
    let mut strongest = (names[0], names[1], 0.0f64);
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            if correlation[i][j].abs() > strongest.2.abs() {
                strongest = (names[i], names[j], correlation[i][j]);
            }
        }
    }

    let mut calibration = SkyCameraCalibration {
        model,
        fitted: true,
        parameters,
        correlation,
        shots: sightings.len(),
        used: suns.len(),
        rejected,
        rms_residual_deg,
        max_residual_deg,
        rms_residual_px,
        track_span_deg,
        off_axis_range_deg,
        strongest_correlation: strongest,
        iterations,
        converged,
        verdict: Verdict::Ok,
        reasons: Vec::new(),
    };
    judge(&mut calibration, options);
    Ok(calibration)
}

/// σ of each parameter and their correlation matrix: `variance · (JᵀJ)⁻¹`,
/// through the SVD of J with its columns scaled to unit length, singular
/// values under 1e-12 of the largest raised to it (an undetermined
/// direction gets a huge, finite σ and correlations near ±1).
fn covariance(j: &DMatrix<f64>, variance: f64) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = j.ncols();
    let norms: Vec<f64> = (0..n).map(|k| j.column(k).norm().max(1e-300)).collect();
    let mut scaled = j.clone();
    for (k, s) in norms.iter().enumerate() {
        scaled.column_mut(k).scale_mut(1.0 / s);
    }
    let svd = scaled.svd(false, true);
    let Some(vt) = svd.v_t else {
        return (vec![f64::MAX; n], identity(n));
    };
    let top = svd.singular_values.max().max(1e-300);
    let mut inv = DMatrix::zeros(n, n);
    for (k, &s) in svd.singular_values.iter().enumerate() {
        let s = s.max(1e-12 * top);
        let v = vt.row(k).transpose();
        inv += (&v * v.transpose()) / (s * s);
    }
    let cov: DMatrix<f64> = DMatrix::from_fn(n, n, |a, b| variance.max(0.0) * inv[(a, b)] / (norms[a] * norms[b]));
    let sigma: Vec<f64> = (0..n).map(|k| cov[(k, k)].max(0.0).sqrt()).collect();
    let corr = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| {
                    let d = (inv[(a, a)] * inv[(b, b)]).sqrt();
                    if d > 0.0 && d.is_finite() {
                        (inv[(a, b)] / d).clamp(-1.0, 1.0)
                    } else if a == b {
                        1.0
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    (
        sigma
            .into_iter()
            .map(|s| if s.is_finite() { s } else { f64::MAX })
            .collect(),
        corr,
    )
}

fn identity(n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|a| (0..n).map(|b| f64::from(u8::from(a == b))).collect())
        .collect()
}

/// A calibration that could not be fitted: the nominal model, `failed`.
fn unfitted(nominal: &SkyCameraModel, shots: usize, rejected: Vec<Rejected>, reason: String) -> SkyCameraCalibration {
    SkyCameraCalibration {
        model: *nominal,
        fitted: false,
        parameters: Vec::new(),
        correlation: Vec::new(),
        shots,
        used: 0,
        rejected,
        rms_residual_deg: 0.0,
        max_residual_deg: 0.0,
        rms_residual_px: 0.0,
        track_span_deg: 0.0,
        off_axis_range_deg: (0.0, 0.0),
        strongest_correlation: ("", "", 0.0),
        iterations: 0,
        converged: false,
        verdict: Verdict::Failed,
        reasons: vec![reason],
    }
}

/// Holds a fitted calibration's figures to `options`' thresholds.
fn judge(c: &mut SkyCameraCalibration, o: &CalibrationOptions) {
    let mut worst = Verdict::Ok;
    let mut say = |v: Verdict, reason: String| {
        worst = worst.max(v);
        c.reasons.push(format!("{v}: {reason}"));
    };
    let gate = |x: f64, poor: f64, failed: f64| {
        if x > failed {
            Verdict::Failed
        } else if x > poor {
            Verdict::Poor
        } else {
            Verdict::Ok
        }
    };
    let span = c.track_span_deg;
    let v = if span < o.failed_track_deg {
        Verdict::Failed
    } else if span < o.poor_track_deg {
        Verdict::Poor
    } else {
        Verdict::Ok
    };
    if v != Verdict::Ok {
        say(
            v,
            format!(
                "track too short: the sun moved {span:.1}° (poor under {}°, failed under {}°)",
                o.poor_track_deg, o.failed_track_deg
            ),
        );
    }
    let v = gate(c.rms_residual_deg, o.poor_residual_deg, o.failed_residual_deg);
    if v != Verdict::Ok {
        say(
            v,
            format!(
                "residual {:.3}° RMS over threshold (poor over {}°, failed over {}°)",
                c.rms_residual_deg, o.poor_residual_deg, o.failed_residual_deg
            ),
        );
    }
    let orientation_sigma = c.parameters.iter().take(3).map(|p| p.sigma).fold(0.0, f64::max);
    let v = gate(
        orientation_sigma,
        o.poor_orientation_sigma_deg,
        o.failed_orientation_sigma_deg,
    );
    if v != Verdict::Ok {
        say(
            v,
            format!(
                "orientation uncertain: σ up to {orientation_sigma:.3}° (poor over {}°, failed over {}°)",
                o.poor_orientation_sigma_deg, o.failed_orientation_sigma_deg
            ),
        );
    }
    let (a, b, r) = c.strongest_correlation;
    let v = gate(r.abs(), o.poor_correlation, o.failed_correlation);
    if v != Verdict::Ok {
        say(
            v,
            format!(
                "ill-conditioned: {a} and {b} correlate at {r:.6} (poor over {}, failed over {}): the track cannot tell them apart",
                o.poor_correlation, o.failed_correlation
            ),
        );
    }
    let fraction = c.rejected.len() as f64 / c.shots.max(1) as f64;
    let v = gate(fraction, o.poor_rejected_fraction, 2.0 * o.poor_rejected_fraction);
    if v != Verdict::Ok {
        say(
            v,
            format!(
                "{} of {} sun shots rejected (poor over {:.0}%, failed over {:.0}%)",
                c.rejected.len(),
                c.shots,
                100.0 * o.poor_rejected_fraction,
                200.0 * o.poor_rejected_fraction
            ),
        );
    }
    if !c.converged {
        say(Verdict::Poor, "the fit did not converge in 200 iterations".into());
    }
    c.verdict = worst;
}
