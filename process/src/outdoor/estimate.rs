//! The pseudo-albedos of each cell (thesis §5.4, eqs. 5.11–5.12
//! generalized to N photos): for every photo k that sees the cell,
//!
//! `π I⁽ᵏ⁾ = ρ^se E_se⁽ᵏ⁾ + ρ^sun E_sun⁽ᵏ⁾`,
//!
//! with `E_sun⁽ᵏ⁾ = 0` where the sun-visibility test found the cell
//! shadowed. Per channel, the two unknowns come from weighted least squares
//! on the relative residual (the light varies tenfold over a day), with
//! Huber reweighting against stray outliers and whole photos rejected when
//! their median log ratio to the fit says their exposure is wrong. The
//! one-bounce term of `E_se` uses the neighbours' current pseudo-albedos, so
//! the fit is repeated a few times (each pass multiplies the bounce error by
//! about the albedo times the view factor, ≲ 0.2).
//!
//! A cell needs a sunlit and a shadowed view to separate ρ^sun from ρ^se.
//! Cells never seen sunlit, never seen shadowed, or whose 2 × 2 system is
//! ill-conditioned (a large column-scaled condition number, or a ρ that
//! amplifies one observation's relative error more than
//! [`ReflectanceSettings::max_amplification`], as a grazing sun does) are
//! reported and filled from their face (§5.4): the
//! face's median ratio `k = ρ^sun / ρ^se` over its solved cells (or the
//! surface's, or the scene's) ties the two, and the cell's own photos fit
//! the one remaining unknown, so its texture is kept. Cells no photo saw
//! take the median of their nearest seen neighbours on the face.

use chrono::{DateTime, Utc};
use nalgebra::{Matrix2, Vector2};
use rayon::prelude::*;

use super::OutdoorError;
use super::cell_irradiance::{GatherSettings, TimeLight, gather};
use super::grid::Grid;
use super::observation::{Footprint, Observation, SamplingReport, observe};
use super::photo::{Illumination, Photo};
use crate::render::Scene;

/// Knobs of the reflectance recovery.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReflectanceSettings {
    /// Grid spacing, metres.
    pub spacing_m: f64,
    /// Irradiance gathering.
    pub gather: GatherSettings,
    /// Fit passes (the one-bounce term is updated between them).
    pub passes: usize,
    /// Huber threshold on the relative residual.
    pub huber_relative: f64,
    /// A photo whose level |ln(observed / fitted)| (trimmed mean of its
    /// cells' ratios) exceeds this is an outlier.
    pub outlier_log_ratio: f64,
    /// Cells whose column-scaled normal matrix has a larger condition number are filled.
    pub max_condition: f64,
    /// Cells whose ρ^sun or ρ^se amplifies the photos' relative error by
    /// more than this are filled: `σ(ρ)/ρ` per unit relative error of one
    /// observation, `√(n (AᵀWA)⁻¹ᵢᵢ) / min(ρ^se, ρ^sun)` over the cell's n rows (one
    /// sunlit and one shadowed view with sun and sky alike give √10 ≈ 3.2;
    /// a sun four times the sky, 1.8). The column-scaled condition number misses the
    /// common case of a sun that only grazes the face: a sunlit view whose
    /// sun term is 5% of the sky term separates ρ^sun from ρ^se, but a 1%
    /// error in its radiance moves ρ^sun by 20%.
    pub max_amplification: f64,
    /// Where a pixel's footprint must lie to be credited to a cell.
    pub footprint: Footprint,
    /// Smallest relative noise assumed when stating uncertainty.
    pub noise_floor: f64,
    /// A photo's time matches an illumination within this many seconds.
    pub time_tolerance_s: f64,
}

impl Default for ReflectanceSettings {
    fn default() -> Self {
        ReflectanceSettings {
            spacing_m: 2.0,
            gather: GatherSettings::default(),
            passes: 3,
            huber_relative: 0.05,
            outlier_log_ratio: 0.1,
            max_condition: 50.0,
            max_amplification: 5.0,
            footprint: Footprint::Face,
            noise_floor: 0.01,
            time_tolerance_s: 120.0,
        }
    }
}

/// How a cell's pseudo-albedos were obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellStatus {
    /// Both from its own sunlit and shadowed views.
    Solved,
    /// Never seen sunlit: ρ^se fitted, ρ^sun from the face's ratio.
    NeverSunlit,
    /// Never seen shadowed: one unknown fitted through the face's ratio.
    NeverShadowed,
    /// Sunlit and shadowed views, but too alike to separate: as `NeverShadowed`.
    IllConditioned,
    /// No photo saw it: the median of its nearest seen neighbours.
    Unseen,
    /// Read from a materials file ([`super::atlas`]); its findings are in
    /// the file's diagnostics.
    FromFile,
}

/// One cell's pseudo-albedos and how far to trust them.
#[derive(Debug, Clone, PartialEq)]
pub struct CellEstimate {
    /// ρ^sun per channel.
    pub rho_sun: [f64; 3],
    /// ρ^se per channel.
    pub rho_se: [f64; 3],
    /// Stated standard uncertainty of ρ^sun per channel.
    pub sigma_sun: [f64; 3],
    /// Stated standard uncertainty of ρ^se per channel.
    pub sigma_se: [f64; 3],
    /// How they were obtained.
    pub status: CellStatus,
    /// Condition number of the column-scaled 2 × 2 normal matrix (green
    /// channel); infinite when only one lighting state was seen.
    pub condition: f64,
    /// How much one observation's relative error is amplified in the worse
    /// of ρ^sun and ρ^se (all channels; see
    /// [`ReflectanceSettings::max_amplification`]); infinite when not fitted.
    pub amplification: f64,
    /// Observations used (photo × lighting state).
    pub observations: usize,
    /// Weighted RMS relative residual of the fit (0 when not fitted).
    pub rms_relative: f64,
}

/// What the fit made of each photo.
#[derive(Debug, Clone, PartialEq)]
pub struct PhotoCheck {
    /// The photo's label.
    pub label: String,
    /// ln of the trimmed mean (10% cut each side) of observed / fitted over its solved cells.
    pub median_log_ratio: f64,
    /// Observations it contributed.
    pub observations: usize,
    /// Rejected as an outlier (wrong exposure, wrong pose, …).
    pub outlier: bool,
}

/// The recovered pseudo-albedos and every diagnostic.
#[derive(Debug, Clone)]
pub struct Reflectance {
    /// The grid.
    pub grid: Grid,
    /// One estimate per grid cell.
    pub cells: Vec<CellEstimate>,
    /// One check per photo.
    pub photos: Vec<PhotoCheck>,
    /// Pixels used and dropped.
    pub sampling: SamplingReport,
    /// Per face, the median ρ^sun / ρ^se used to fill its cells.
    pub face_ratio: Vec<[f64; 3]>,
    /// Human-readable findings: faces never sunlit, photos rejected, …
    pub diagnostics: Vec<String>,
}

impl Reflectance {
    /// Cells with each status.
    pub fn count(&self, status: CellStatus) -> usize {
        self.cells.iter().filter(|c| c.status == status).count()
    }
}

/// Index into `lights` of the illumination at `time`.
fn light_index(lights: &[Illumination], time: DateTime<Utc>, tolerance_s: f64) -> Option<usize> {
    lights
        .iter()
        .enumerate()
        .map(|(i, l)| (i, (l.time - time).num_milliseconds().abs() as f64 / 1000.0))
        .filter(|(_, d)| *d <= tolerance_s)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// One row of a cell's system: y = π I, x = (E_se, E_sun), base weight.
#[derive(Clone, Copy)]
struct Row {
    y: [f64; 3],
    e_se: [f64; 3],
    e_sun: [f64; 3],
    w: f64,
    sunlit: bool,
}

fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// The mean of `v` without its lowest and highest tenth: the level of a
/// photo's observed-to-fitted ratios. Unlike their median it is not pulled
/// down by the skewed Monte Carlo noise of shaded walls, which had noisy
/// but correctly exposed photos rejected as outliers.
fn trimmed_mean(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let cut = v.len() / 10;
    let kept = &v[cut..v.len() - cut];
    Some(kept.iter().sum::<f64>() / kept.len() as f64)
}

/// Weighted least squares of `y ≈ a·x1 + b·x2` on relative residuals with
/// Huber reweighting; returns (a, b, covariance scale matrix (AᵀWA)⁻¹,
/// weighted residual variance, condition number).
fn fit2(rows: &[(f64, f64, f64, f64)], huber: f64) -> Option<(Vector2<f64>, Matrix2<f64>, f64, f64)> {
    let mut robust = vec![1.0; rows.len()];
    // The scale of each relative residual: the observation at first, then
    // the fitted value. Dividing by the noisy observation itself favours the
    // observations that came out low (a bias of about the relative variance
    // of one observation, percents on noisy photographs).
    let mut scale: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let mut sol = None;
    for _ in 0..4 {
        let mut m = Matrix2::zeros();
        let mut r = Vector2::zeros();
        for (((y, x1, x2, w), h), s) in rows.iter().zip(&robust).zip(&scale) {
            let wy = w * h / s.max(1e-12).powi(2);
            let x = Vector2::new(*x1, *x2);
            m += x * x.transpose() * wy;
            r += x * (wy * y);
        }
        let inv = m.try_inverse()?;
        let p = inv * r;
        let mut rels = Vec::with_capacity(rows.len());
        for ((y, x1, x2, _), s) in rows.iter().zip(scale.iter_mut()) {
            let fitted = p[0] * x1 + p[1] * x2;
            if fitted > 0.0 {
                *s = fitted;
            }
            rels.push(((y - fitted) / s.max(1e-12)).abs());
        }
        // Huber's threshold at 1.345 robust standard deviations of the
        // residuals (MAD), never below `huber`: on noisy photographs a fixed
        // small threshold turns the fit into a median, which is biased low
        // for the skewed noise of shaded walls (−10% at 2 samples per pixel).
        let mut sorted = rels.clone();
        let threshold = median(&mut sorted).map_or(huber, |mad| (1.345 * 1.4826 * mad).max(huber));
        for (rel, h) in rels.iter().zip(robust.iter_mut()) {
            *h = if *rel <= threshold { 1.0 } else { threshold / rel };
        }
        // Condition of the column-scaled matrix.
        let d = Vector2::new(m[(0, 0)].sqrt(), m[(1, 1)].sqrt());
        let scaled = Matrix2::new(1.0, m[(0, 1)] / (d[0] * d[1]), m[(1, 0)] / (d[0] * d[1]), 1.0);
        let eig = scaled.symmetric_eigenvalues();
        let cond = eig.max() / eig.min().max(1e-300);
        sol = Some((p, inv, cond));
    }
    let (p, inv, cond) = sol?;
    let mut rss = 0.0;
    for (((y, x1, x2, w), h), s) in rows.iter().zip(&robust).zip(&scale) {
        let rel = (y - p[0] * x1 - p[1] * x2) / s.max(1e-12);
        rss += w * h * rel * rel;
    }
    let dof = rows.len() as f64 - 2.0;
    let var = if dof > 0.0 { rss / dof } else { 0.0 };
    Some((p, inv, var, cond))
}

/// One-unknown weighted least squares `y ≈ a·x` on relative residuals:
/// (a, 1/Σw x²/y², residual variance).
fn fit1(rows: &[(f64, f64, f64)]) -> Option<(f64, f64, f64)> {
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for (y, x, w) in rows {
        let wy = w / y.max(1e-12).powi(2);
        sxx += wy * x * x;
        sxy += wy * x * y;
    }
    if sxx <= 0.0 {
        return None;
    }
    let a = sxy / sxx;
    let rss: f64 = rows
        .iter()
        .map(|(y, x, w)| w * ((y - a * x) / y.max(1e-12)).powi(2))
        .sum();
    let dof = rows.len() as f64 - 1.0;
    Some((a, 1.0 / sxx, if dof > 0.0 { rss / dof } else { 0.0 }))
}

/// A cell's rows under the current pseudo-albedos.
fn rows_of(
    cell: usize,
    obs: &[&Observation],
    lights: &[TimeLight],
    rho_sun: &[[f64; 3]],
    rho_se: &[[f64; 3]],
    active: &[bool],
) -> Vec<Row> {
    let mean_w = {
        let ws: Vec<f64> = obs.iter().filter(|o| active[o.photo]).map(|o| o.weight).collect();
        (ws.iter().sum::<f64>() / ws.len().max(1) as f64).max(1e-12)
    };
    obs.iter()
        .filter(|o| active[o.photo])
        .map(|o| {
            let tl = &lights[o.time];
            Row {
                y: o.radiance.map(|l| std::f64::consts::PI * l),
                e_se: tl.se_irradiance(cell, rho_sun, rho_se),
                e_sun: if o.sunlit { tl.sun_irradiance(cell) } else { [0.0; 3] },
                w: o.weight / mean_w,
                sunlit: o.sunlit,
            }
        })
        .collect()
}

/// A face's ratio ρ^sun/ρ^se is taken from its own solved cells only when it
/// has at least this many (else from its surface, else the scene): on a face
/// the sun only grazes, the few cells that pass are the noisiest (a north
/// wall's ratio came out 3.5 from three of them).
const MIN_RATIO_CELLS: usize = 10;

/// A photo is judged an outlier only on at least this many solved cells.
pub const MIN_OUTLIER_EVIDENCE: usize = 30;

/// Sunlit rows whose sun term is at least this fraction of the sky term count as "seen sunlit".
const SUNLIT_SIGNIFICANT: f64 = 0.05;

fn solve_cell(rows: &[Row], settings: &ReflectanceSettings) -> (CellEstimate, bool) {
    let lit = rows
        .iter()
        .any(|r| r.sunlit && r.e_sun[1] > SUNLIT_SIGNIFICANT * r.e_se[1]);
    let shadowed = rows.iter().any(|r| !r.sunlit);
    let mut est = CellEstimate {
        rho_sun: [0.0; 3],
        rho_se: [0.0; 3],
        sigma_sun: [f64::INFINITY; 3],
        sigma_se: [f64::INFINITY; 3],
        status: if rows.is_empty() {
            CellStatus::Unseen
        } else if !lit {
            CellStatus::NeverSunlit
        } else if !shadowed {
            CellStatus::NeverShadowed
        } else {
            CellStatus::Solved
        },
        condition: f64::INFINITY,
        amplification: f64::INFINITY,
        observations: rows.len(),
        rms_relative: 0.0,
    };
    if est.status != CellStatus::Solved {
        return (est, false);
    }
    let floor2 = settings.noise_floor.powi(2);
    let mut var_all = 0.0;
    let mut amplification: f64 = 0.0;
    for ch in 0..3 {
        let sys: Vec<(f64, f64, f64, f64)> = rows.iter().map(|r| (r.y[ch], r.e_se[ch], r.e_sun[ch], r.w)).collect();
        let Some((p, inv, var, cond)) = fit2(&sys, settings.huber_relative) else {
            est.status = CellStatus::IllConditioned;
            return (est, false);
        };
        if ch == 1 {
            est.condition = cond;
        }
        // Relative to the smaller of the two estimates: a ρ^sun blown up by
        // a grazing sun would otherwise look well determined against itself.
        let n = rows.len() as f64;
        let scale = p[0].abs().min(p[1].abs()).max(1e-12);
        amplification = amplification
            .max((n * inv[(0, 0)]).max(0.0).sqrt() / scale)
            .max((n * inv[(1, 1)]).max(0.0).sqrt() / scale);
        let s2 = var.max(floor2);
        var_all += var / 3.0;
        est.rho_se[ch] = p[0];
        est.rho_sun[ch] = p[1];
        est.sigma_se[ch] = (s2 * inv[(0, 0)]).sqrt();
        est.sigma_sun[ch] = (s2 * inv[(1, 1)]).sqrt();
    }
    est.rms_relative = var_all.sqrt();
    est.amplification = amplification;
    if amplification > settings.max_amplification
        || est.condition > settings.max_condition
        || est.rho_se.iter().chain(&est.rho_sun).any(|v| !v.is_finite())
    {
        est.status = CellStatus::IllConditioned;
        return (est, false);
    }
    (est, true)
}

/// Fills a cell that could not be solved alone, with the ratio `k` (and its
/// spread) of its face.
fn fill_cell(est: &mut CellEstimate, rows: &[Row], k: [f64; 3], spread: [f64; 3], settings: &ReflectanceSettings) {
    let floor2 = settings.noise_floor.powi(2);
    for ch in 0..3 {
        let sys: Vec<(f64, f64, f64)> = rows
            .iter()
            .map(|r| (r.y[ch], r.e_se[ch] + k[ch] * r.e_sun[ch], r.w))
            .collect();
        if let Some((a, inv, var)) = fit1(&sys) {
            est.rho_se[ch] = a;
            est.rho_sun[ch] = k[ch] * a;
            let s2 = var.max(floor2);
            est.sigma_se[ch] = (s2 * inv).sqrt();
            // The ratio's spread over the face dominates ρ^sun's uncertainty.
            est.sigma_sun[ch] = ((k[ch] * est.sigma_se[ch]).powi(2) + (spread[ch] * a).powi(2)).sqrt();
            est.rms_relative = var.sqrt();
        }
    }
}

/// Recovers the pseudo-albedos of the `targets` surfaces of `scene` from
/// `photos`, each lit by the illumination in `lights` at its time.
/// Returns the estimates and the light gathered on the grid at each of
/// `lights`' times.
pub fn recover_reflectance(
    scene: &Scene,
    targets: &[usize],
    photos: &[Photo],
    lights: &[Illumination],
    settings: &ReflectanceSettings,
) -> Result<(Reflectance, Vec<TimeLight>), OutdoorError> {
    if photos.is_empty() {
        return Err(OutdoorError::NoPhotos);
    }
    let times: Vec<usize> = photos
        .iter()
        .map(|p| {
            light_index(lights, p.time, settings.time_tolerance_s).ok_or_else(|| OutdoorError::NoIllumination {
                photo: p.label.clone(),
                time: p.time,
            })
        })
        .collect::<Result<_, _>>()?;
    let viewpoints: Vec<_> = photos.iter().map(|p| p.rig.position).collect();
    let grid = Grid::new(scene, targets, settings.spacing_m, &viewpoints)?;
    let (obs, sampling) = observe(scene, &grid, photos, lights, &times, settings.footprint)?;
    let tls: Vec<TimeLight> = lights
        .iter()
        .map(|l| gather(scene, &grid, l, &settings.gather))
        .collect();
    let n = grid.cells.len();
    let mut by_cell: Vec<Vec<&Observation>> = vec![Vec::new(); n];
    for o in &obs {
        by_cell[o.cell].push(o);
    }
    let mut active = vec![true; photos.len()];
    let mut rho_sun = vec![[0.0; 3]; n];
    let mut rho_se = vec![[0.0; 3]; n];
    let mut estimates = Vec::new();
    let mut face_ratio = vec![[1.0; 3]; grid.faces.len()];
    let mut diagnostics = Vec::new();
    let mut checks = Vec::new();
    let mut pass = 0;
    let mut extra = 0;
    while pass < settings.passes + extra {
        pass += 1;
        let rows: Vec<Vec<Row>> = (0..n)
            .into_par_iter()
            .map(|c| rows_of(c, &by_cell[c], &tls, &rho_sun, &rho_se, &active))
            .collect();
        let solved: Vec<(CellEstimate, bool)> = rows.par_iter().map(|r| solve_cell(r, settings)).collect();
        let mut est: Vec<CellEstimate> = solved.iter().map(|s| s.0.clone()).collect();
        // Face, surface and scene ratios from the solved cells.
        let ratio_of = |ids: &mut dyn Iterator<Item = usize>| -> Option<([f64; 3], [f64; 3])> {
            let ids: Vec<usize> = ids.filter(|&i| solved[i].1).collect();
            if ids.len() < MIN_RATIO_CELLS {
                return None;
            }
            let mut k = [0.0; 3];
            let mut spread = [0.0; 3];
            for ch in 0..3 {
                let mut r: Vec<f64> = ids
                    .iter()
                    .map(|&i| est[i].rho_sun[ch] / est[i].rho_se[ch].max(1e-9))
                    .collect();
                k[ch] = median(&mut r)?;
                let mut dev: Vec<f64> = r.iter().map(|x| (x - k[ch]).abs()).collect();
                spread[ch] = 1.4826 * median(&mut dev)? / k[ch].abs().max(1e-9);
            }
            Some((k, spread))
        };
        let scene_ratio = ratio_of(&mut (0..n)).unwrap_or(([1.0; 3], [0.5; 3]));
        let mut face_k = Vec::with_capacity(grid.faces.len());
        for f in &grid.faces {
            let k = ratio_of(&mut f.cells.iter().copied())
                .or_else(|| ratio_of(&mut (0..n).filter(|&i| grid.cells[i].surface == f.surface)))
                .unwrap_or(scene_ratio);
            face_k.push(k);
        }
        for c in 0..n {
            if !solved[c].1 && est[c].status != CellStatus::Unseen {
                let (k, spread) = face_k[grid.cells[c].face];
                fill_cell(&mut est[c], &rows[c], k, spread, settings);
            }
        }
        // Unseen cells: nearest seen neighbours on the face.
        for c in 0..n {
            if est[c].status != CellStatus::Unseen {
                continue;
            }
            let mut filled = false;
            for ring in 1..=4 {
                let nb: Vec<usize> = grid
                    .neighbours(c, ring)
                    .into_iter()
                    .filter(|&j| est[j].status != CellStatus::Unseen)
                    .collect();
                if nb.len() >= 2 || (ring == 4 && !nb.is_empty()) {
                    for ch in 0..3 {
                        let mut a: Vec<f64> = nb.iter().map(|&j| est[j].rho_sun[ch]).collect();
                        let mut b: Vec<f64> = nb.iter().map(|&j| est[j].rho_se[ch]).collect();
                        let (ma, mb) = (median(&mut a).unwrap_or(0.0), median(&mut b).unwrap_or(0.0));
                        let sa = a.iter().map(|x| (x - ma).abs()).fold(0.0, f64::max);
                        let sb = b.iter().map(|x| (x - mb).abs()).fold(0.0, f64::max);
                        est[c].rho_sun[ch] = ma;
                        est[c].rho_se[ch] = mb;
                        est[c].sigma_sun[ch] = sa.max(settings.noise_floor * ma);
                        est[c].sigma_se[ch] = sb.max(settings.noise_floor * mb);
                    }
                    filled = true;
                    break;
                }
            }
            if !filled {
                // Nothing seen on the face: the surface's median.
                let same: Vec<usize> = (0..n)
                    .filter(|&j| grid.cells[j].surface == grid.cells[c].surface && est[j].status != CellStatus::Unseen)
                    .collect();
                for ch in 0..3 {
                    let mut a: Vec<f64> = same.iter().map(|&j| est[j].rho_sun[ch]).collect();
                    let mut b: Vec<f64> = same.iter().map(|&j| est[j].rho_se[ch]).collect();
                    est[c].rho_sun[ch] = median(&mut a).unwrap_or(0.0);
                    est[c].rho_se[ch] = median(&mut b).unwrap_or(0.0);
                }
            }
        }
        for c in 0..n {
            rho_sun[c] = est[c].rho_sun.map(|v| v.max(0.0));
            rho_se[c] = est[c].rho_se.map(|v| v.max(0.0));
        }
        face_ratio = face_k.iter().map(|f| f.0).collect();
        // Photos: median log ratio of observed to fitted.
        checks = photos
            .iter()
            .enumerate()
            .map(|(p, photo)| {
                let mut ratios: Vec<f64> = obs
                    .iter()
                    .filter(|o| o.photo == p && est[o.cell].status == CellStatus::Solved)
                    .filter_map(|o| {
                        let tl = &tls[o.time];
                        let e_se = tl.se_irradiance(o.cell, &rho_sun, &rho_se);
                        let e_sun = if o.sunlit { tl.sun_irradiance(o.cell) } else { [0.0; 3] };
                        let v: f64 = (0..3)
                            .map(|ch| {
                                let fit = rho_se[o.cell][ch] * e_se[ch] + rho_sun[o.cell][ch] * e_sun[ch];
                                std::f64::consts::PI * o.radiance[ch] / fit
                            })
                            .sum::<f64>()
                            / 3.0;
                        v.is_finite().then_some(v)
                    })
                    .collect();
                let count = ratios.len();
                PhotoCheck {
                    label: photo.label.clone(),
                    median_log_ratio: trimmed_mean(&mut ratios).filter(|m| *m > 0.0).map_or(0.0, f64::ln),
                    observations: count,
                    outlier: !active[p],
                }
            })
            .collect::<Vec<_>>();
        estimates = est;
        // Reject the worst photo beyond the threshold, and refit.
        if let Some((worst, c)) = checks
            .iter()
            .enumerate()
            .filter(|(p, c)| {
                active[*p]
                    && c.observations >= MIN_OUTLIER_EVIDENCE
                    && c.median_log_ratio.abs() > settings.outlier_log_ratio
            })
            .max_by(|a, b| a.1.median_log_ratio.abs().total_cmp(&b.1.median_log_ratio.abs()))
            && active.iter().filter(|a| **a).count() > 1
        {
            active[worst] = false;
            diagnostics.push(format!(
                "photo {:?} rejected as an outlier: its radiance is {:.1}% off the fit of the others (median over {} cells); check its exposure metadata",
                c.label,
                (c.median_log_ratio.exp() - 1.0) * 100.0,
                c.observations
            ));
            extra = (pass + 2).saturating_sub(settings.passes).max(extra);
        }
    }
    for (p, c) in checks.iter_mut().enumerate() {
        c.outlier = !active[p];
    }
    for (fi, f) in grid.faces.iter().enumerate() {
        let count = |s: CellStatus| f.cells.iter().filter(|&&c| estimates[c].status == s).count();
        let name = scene.surfaces()[f.surface].as_str();
        let (ns, nsh, unseen) = (
            count(CellStatus::NeverSunlit),
            count(CellStatus::NeverShadowed),
            count(CellStatus::Unseen),
        );
        if ns > 0 && ns + unseen == f.cells.len() {
            diagnostics.push(format!(
                "face {fi} of {name:?} (normal {:.2?}): never seen sunlit; ρ_sun filled with ratio {:.3?} from neighbouring faces of the same surface or the scene",
                f.normal.as_slice(),
                face_ratio[fi]
            ));
        } else if ns + nsh + unseen > 0 {
            diagnostics.push(format!(
                "face {fi} of {name:?}: {ns} cells never sunlit, {nsh} never shadowed, {unseen} unseen of {}; filled with the face's ratio ρ_sun/ρ_se = {:.3?}",
                f.cells.len(),
                face_ratio[fi]
            ));
        }
    }
    Ok((
        Reflectance {
            grid,
            cells: estimates,
            photos: checks,
            sampling,
            face_ratio,
            diagnostics,
        },
        tls,
    ))
}
