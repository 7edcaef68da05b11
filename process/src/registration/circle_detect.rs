//! The thesis's own targets found in a photograph (§3.3.1): flat dark
//! square plates with a white circle in the middle and no identity.
//!
//! 1. **Candidates by a template sweep at several scales.** A template of
//!    a white square inscribed in the circle on its dark plate is swept
//!    over the image at radii from `min_radius_px` up, a factor 1.25
//!    apart; its normalized cross-correlation with the image comes from
//!    integral images in constant time a pixel (the thesis uses the sum of
//!    squared differences; NCC is the same measure made independent of
//!    exposure). As in the thesis, the threshold is liberal: "template
//!    matching is only effective at locating candidate target locations",
//!    since a circle seen obliquely is an ellipse of three more degrees of
//!    freedom. Local maxima over position, then over scale, are the candidates.
//! 2. **Verification by an ellipse fit.** From each candidate, rays are cast
//!    outward; along each, the white-to-dark edge is the steepest descent,
//!    located to sub-pixel by the crossing of the mean of the levels just
//!    inside and outside it. A direct least-squares ellipse
//!    ([`super::ellipse`]) is fitted to the edge points robustly (an
//!    occluder's edge points drop out), and the rays are cast again from
//!    the fitted centre. The thesis then "evaluate[s] the match, again
//!    using SSD ... equivalent to matching against the best possible
//!    elliptical template": here the residual of the best two-level
//!    elliptical template (white inside the ellipse, dark in the ring to
//!    1.5 times its size), relative to its contrast.
//!
//! A detection gives the five parameters of the ellipse (centre, axes,
//! angle), its edge points (for [`super::circle_search`] to refit in the
//! lens's undistorted frame) and its figures.
//!
//! **Speed, with the same results.** The integral images hold exact
//! integer sums (`u32`, wrapping), so every score is the one `f64` sums
//! would give; a window is first tested for contrast without divisions
//! and its sum of squares read only if it passes; only scores above
//! `min_ncc` are kept (no lower score can stop a local maximum), row by
//! row in parallel. Candidates are verified in parallel a few at a time
//! and taken in order, as if one by one. On a 2048 × 1536 photograph of
//! 100 targets that is 2.1–2.7 times faster than `f64` integral images
//! and a full score grid per scale, with the same detections to the bit
//! (BENCHMARKS.md, "Camera pose from targets").

use super::ellipse::{Ellipse, fit_ellipse_robust};
use rayon::prelude::*;

/// The largest radius swept, pixels: its window (2 × 1440 + 1 pixels a
/// side) sums to under 2³¹ codes, as the sweep's integer sums need.
pub const MAX_RADIUS_PX: f64 = 960.0;

/// How circle targets are looked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleDetectorSettings {
    /// Smallest radius of a circle's image, pixels.
    pub min_radius_px: f64,
    /// Largest radius, pixels (also capped at an eighth of the image's
    /// smaller side, and at [`MAX_RADIUS_PX`]).
    pub max_radius_px: f64,
    /// Least normalized cross-correlation of a candidate (liberal).
    pub min_ncc: f64,
    /// Least contrast between the white circle and its plate, codes.
    pub min_contrast: f64,
    /// Rays cast from each candidate.
    pub rays: usize,
    /// Least fraction of the rays whose edge point the fit keeps.
    pub min_edge_fraction: f64,
    /// Largest RMS distance of the kept edge points from the ellipse, pixels.
    pub max_fit_rms_px: f64,
    /// Largest residual of the elliptical template, relative to its contrast.
    pub max_template_residual: f64,
    /// Least ratio of the minor to the major axis.
    pub min_axis_ratio: f64,
    /// Least ratio of the white level to the plate's.
    pub min_contrast_ratio: f64,
    /// Largest standard deviation inside the ellipse, relative to the contrast.
    pub max_inside_spread: f64,
    /// Largest standard deviation over the ring around it, relative to the contrast.
    pub max_ring_spread: f64,
    /// Least fraction of the perimeter with an edge across it.
    pub min_perimeter_edges: f64,
}

impl Default for CircleDetectorSettings {
    fn default() -> Self {
        CircleDetectorSettings {
            min_radius_px: 3.0,
            max_radius_px: 120.0,
            min_ncc: 0.45,
            min_contrast: 6.0,
            rays: 64,
            min_edge_fraction: 0.6,
            max_fit_rms_px: 0.6,
            max_template_residual: 0.3,
            min_axis_ratio: 0.2,
            min_contrast_ratio: 2.0,
            max_inside_spread: 0.2,
            max_ring_spread: 0.15,
            min_perimeter_edges: 0.8,
        }
    }
}

/// One circle target found in a photograph.
#[derive(Debug, Clone, PartialEq)]
pub struct CircleDetection {
    /// The ellipse of the white circle's edge, pixels.
    pub ellipse: Ellipse,
    /// The edge points the fit kept, pixels.
    pub edge_points: Vec<(f64, f64)>,
    /// RMS distance of the edge points from the ellipse, pixels.
    pub fit_rms_px: f64,
    /// Residual of the best elliptical template, relative to its contrast (0 perfect).
    pub template_residual: f64,
    /// White level minus plate level, codes.
    pub contrast: f64,
    /// White level over plate level.
    pub contrast_ratio: f64,
    /// Standard deviation of the levels inside the ellipse, relative to the contrast.
    pub inside_spread: f64,
    /// Standard deviation of the levels in the ring around it, relative to the contrast.
    pub ring_spread: f64,
    /// Fraction of the ellipse's perimeter with a white-to-dark edge across it.
    pub perimeter_edges: f64,
    /// The candidate's normalized cross-correlation with the template.
    pub ncc: f64,
}

/// Sums over rectangles in constant time: integral images of the codes
/// and of their squares in wrapping `u32` arithmetic. The difference of
/// wrapped prefix sums is the true sum modulo 2³², so a rectangle's sum is
/// exact whenever it is below 2³² (any window of the codes: at most
/// 16.8 million pixels; of their squares: at most 66 051 pixels, beyond
/// which [`Integral::sq`] adds strips). Exact sums make the scores the same
/// as from `f64` integral images, at a quarter of the memory.
struct Integral {
    w: usize,
    sum: Vec<u32>,
    sq: Vec<u32>,
}

impl Integral {
    fn new(gray: &[u8], w: usize, h: usize) -> Integral {
        let s = w + 1;
        let mut sum = vec![0u32; s * (h + 1)];
        let mut sq = vec![0u32; s * (h + 1)];
        for y in 0..h {
            let (above, row) = sum.split_at_mut((y + 1) * s);
            let (above_sq, row_sq) = sq.split_at_mut((y + 1) * s);
            let (above, above_sq) = (&above[y * s..], &above_sq[y * s..]);
            let (mut acc, mut acc_sq) = (0u32, 0u32);
            for x in 0..w {
                let v = u32::from(gray[y * w + x]);
                acc = acc.wrapping_add(v);
                acc_sq = acc_sq.wrapping_add(v * v);
                row[x + 1] = above[x + 1].wrapping_add(acc);
                row_sq[x + 1] = above_sq[x + 1].wrapping_add(acc_sq);
            }
        }
        Integral { w, sum, sq }
    }

    /// The wrapped sum of `t` over x in [x0, x1), y in [y0, y1).
    fn rect(&self, t: &[u32], x0: usize, y0: usize, x1: usize, y1: usize) -> u32 {
        let s = self.w + 1;
        t[y1 * s + x1]
            .wrapping_sub(t[y0 * s + x1])
            .wrapping_sub(t[y1 * s + x0])
            .wrapping_add(t[y0 * s + x0])
    }

    /// The wrapped sums of the codes over y in [y0, y1) and x below each
    /// column (`out[x]`, x up to the width): a rectangle's sum over
    /// x in [x0, x1) is `out[x1] - out[x0]`.
    fn column_sums(&self, y0: usize, y1: usize, out: &mut [u32]) {
        let s = self.w + 1;
        let (top, bottom) = (&self.sum[y0 * s..][..s], &self.sum[y1 * s..][..s]);
        for ((o, b), t) in out.iter_mut().zip(bottom).zip(top) {
            *o = b.wrapping_sub(*t);
        }
    }

    /// Sum of the squared codes over x in [x0, x1), y in [y0, y1), in
    /// strips of at most `strip` rows, each below 2³².
    fn sq(&self, x0: usize, y0: usize, x1: usize, y1: usize, strip: usize) -> u64 {
        let mut total = 0u64;
        let mut y = y0;
        while y < y1 {
            let next = (y + strip).min(y1);
            total += u64::from(self.rect(&self.sq, x0, y, x1, next));
            y = next;
        }
        total
    }
}

/// Rows of a strip of `width` pixels whose squared codes sum below 2³².
fn sq_strip_rows(width: usize) -> usize {
    ((u32::MAX as usize) / (255 * 255 * width.max(1))).max(1)
}

/// A candidate from the template sweep.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    x: f64,
    y: f64,
    r: f64,
    ncc: f64,
}

/// The template sweep (module doc, step 1). Each row of the grid is
/// scored in parallel; only scores of at least `min_ncc` are kept (a
/// lower neighbour cannot stop a local maximum), so a row is a short
/// list of (column, score), in column order.
fn sweep(ii: &Integral, w: usize, h: usize, s: &CircleDetectorSettings) -> Vec<Candidate> {
    let r_max = s.max_radius_px.min(w.min(h) as f64 / 8.0).min(MAX_RADIUS_PX);
    let mut out: Vec<Candidate> = Vec::new();
    let mut r = s.min_radius_px.max(2.0);
    while r <= r_max {
        // The inscribed square of the circle, and the plate to 1.5 r.
        let hi = ((0.7 * r).round() as usize).max(1);
        let ho = ((1.5 * r).round() as usize).max(hi + 1);
        // A grid a quarter of the radius apart (rounded up): the peak of the
        // correlation is r wide, and the verification recasts from the fitted centre.
        let step = ((r / 4.0).ceil() as usize).max(1);
        let (n_a, n_w) = (
            ((2 * hi + 1) * (2 * hi + 1)) as f64,
            ((2 * ho + 1) * (2 * ho + 1)) as f64,
        );
        let p = n_a / n_w;
        let (gw, gh) = (
            (w.saturating_sub(2 * ho + 1)) / step + 1,
            (h.saturating_sub(2 * ho + 1)) / step + 1,
        );
        if w <= 2 * ho + 1 || h <= 2 * ho + 1 {
            break;
        }
        let strip = sq_strip_rows(2 * ho + 1);
        // The contrast test below without its divisions, for most windows:
        // sa n_w - sw n_a is exact (integers below 2⁵³) and is the contrast
        // times n_a (n_w - n_a); the divided form differs from the exact
        // contrast by under 1e-13 (three roundings of codes below 256), so a
        // window short of the least contrast by 1e-9 fails both ways.
        let reject_below = (s.min_contrast - 1e-9) * n_a * (n_w - n_a);
        let rows: Vec<Vec<(usize, f64)>> = (0..gh)
            .into_par_iter()
            .map_init(
                || (vec![0u32; w + 1], vec![0u32; w + 1], vec![0.0f64; gw]),
                |(inner, outer, contrast), gy| {
                    let mut row = Vec::new();
                    let cy = ho + gy * step;
                    if cy + ho + 1 > h {
                        return row;
                    }
                    // Column sums over the inner square's rows and the window's:
                    // a window's sum is then the difference of two of them.
                    ii.column_sums(cy - hi, cy + hi + 1, inner);
                    ii.column_sums(cy - ho, cy + ho + 1, outer);
                    // Every window's sa n_w - sw n_a in one loop without branches
                    // (one the compiler vectorizes at step 1); sums of windows
                    // are below 2³¹, so as `i32` they convert exactly.
                    let sums = |x: usize| {
                        let sa = inner[x + ho + hi + 1].wrapping_sub(inner[x + ho - hi]) as i32;
                        let sw = outer[x + 2 * ho + 1].wrapping_sub(outer[x]) as i32;
                        (f64::from(sa), f64::from(sw))
                    };
                    if step == 1 {
                        let (ia, ib) = (&inner[ho + hi + 1..][..gw], &inner[ho - hi..][..gw]);
                        let (oa, ob) = (&outer[2 * ho + 1..][..gw], &outer[..gw]);
                        for ((((c, ia), ib), oa), ob) in contrast.iter_mut().zip(ia).zip(ib).zip(oa).zip(ob) {
                            let sa = f64::from(ia.wrapping_sub(*ib) as i32);
                            let sw = f64::from(oa.wrapping_sub(*ob) as i32);
                            *c = sa * n_w - sw * n_a;
                        }
                    } else {
                        for (gx, c) in contrast.iter_mut().enumerate() {
                            let (sa, sw) = sums(gx * step);
                            *c = sa * n_w - sw * n_a;
                        }
                    }
                    for (gx, c) in contrast.iter().enumerate() {
                        let cx = ho + gx * step;
                        if *c < reject_below || cx + ho + 1 > w {
                            continue;
                        }
                        let (sa, sw) = sums(gx * step);
                        let outer_mean = (sw - sa) / (n_w - n_a);
                        // Too little contrast: the sum of squares is not needed.
                        if sa / n_a - outer_mean < s.min_contrast {
                            continue;
                        }
                        let qw = ii.sq(cx - ho, cy - ho, cx + ho + 1, cy + ho + 1, strip) as f64;
                        let mean = sw / n_w;
                        let var = qw - sw * mean;
                        if var <= 0.0 {
                            continue;
                        }
                        let score = (sa - n_a * mean) / (var * n_a * (1.0 - p)).sqrt();
                        if score >= s.min_ncc {
                            row.push((gx, score));
                        }
                    }
                    row
                },
            )
            .collect();
        // The kept scores of row `gy` in columns gx - 1 ..= gx + 1.
        let near = |gy: usize, gx: usize| {
            let row = &rows[gy];
            let from = row.partition_point(|(x, _)| *x + 1 < gx);
            row[from..].iter().take_while(move |(x, _)| *x <= gx + 1)
        };
        for (gy, row) in rows.iter().enumerate() {
            for &(gx, v) in row {
                let mut is_max = true;
                'n: for ny in gy.saturating_sub(1)..=(gy + 1).min(gh - 1) {
                    for &(nx, o) in near(ny, gx) {
                        let (dy, dx) = (ny as i64 - gy as i64, nx as i64 - gx as i64);
                        if (dx, dy) == (0, 0) {
                            continue;
                        }
                        // Ties broken toward the earlier cell.
                        if o > v || (o == v && (dy, dx) < (0, 0)) {
                            is_max = false;
                            break 'n;
                        }
                    }
                }
                if is_max {
                    out.push(Candidate {
                        x: (ho + gx * step) as f64 + 0.5,
                        y: (ho + gy * step) as f64 + 0.5,
                        r,
                        ncc: v,
                    });
                }
            }
        }
        r *= 1.25;
    }
    // Across scales: the best candidate within its radius of another wins.
    out.sort_by(|a, b| b.ncc.total_cmp(&a.ncc));
    let mut kept: Vec<Candidate> = Vec::new();
    for c in out {
        if kept.iter().all(|k| (k.x - c.x).hypot(k.y - c.y) > 0.8 * k.r.max(c.r)) {
            kept.push(c);
        }
    }
    kept
}

/// Bilinear sample of `gray` at pixel coordinates (pixel centres at half-integers).
fn sample(gray: &[u8], w: usize, h: usize, x: f64, y: f64) -> Option<f64> {
    let (fx, fy) = (x - 0.5, y - 0.5);
    if !(fx >= 0.0 && fy >= 0.0 && fx < (w - 1) as f64 && fy < (h - 1) as f64) {
        return None;
    }
    let (ix, iy) = (fx as usize, fy as usize);
    let (tx, ty) = (fx - ix as f64, fy - iy as f64);
    let at = |x: usize, y: usize| f64::from(gray[y * w + x]);
    Some(
        (1.0 - ty) * ((1.0 - tx) * at(ix, iy) + tx * at(ix + 1, iy))
            + ty * ((1.0 - tx) * at(ix, iy + 1) + tx * at(ix + 1, iy + 1)),
    )
}

/// The white-to-dark edge along the ray from `(x0, y0)` in direction
/// `(dx, dy)` between radii `from` and `to` (module doc, step 2), if its
/// contrast is at least `min_contrast`. `profile` is room for the samples
/// along the ray.
#[allow(clippy::too_many_arguments)]
fn edge_on_ray(
    gray: &[u8],
    w: usize,
    h: usize,
    (x0, y0): (f64, f64),
    (dx, dy): (f64, f64),
    from: f64,
    to: f64,
    min_contrast: f64,
    profile: &mut Vec<f64>,
) -> Option<(f64, f64)> {
    const STEP: f64 = 0.25;
    const LAG: usize = 6; // 1.5 px either side of the edge
    let n = ((to + 2.0) / STEP).ceil() as usize;
    let at = |k: usize| sample(gray, w, h, x0 + dx * k as f64 * STEP, y0 + dy * k as f64 * STEP);
    // The ray must lie in the image out to 2 px past `to`. Its sample
    // points' coordinates are monotone in k, so they all lie in the image
    // (a rectangle) if the two ends do.
    at(0)?;
    at(n)?;
    let first = ((from / STEP) as usize).max(LAG);
    let last = ((to / STEP) as usize).min(n.saturating_sub(LAG));
    if first >= last {
        return None;
    }
    // The samples the search reads: k in [first - LAG, last + LAG].
    let base = first - LAG;
    profile.clear();
    for k in base..=last + LAG {
        profile.push(at(k)?);
    }
    let p = |k: usize| profile[k - base];
    // Steepest descent, over ±1 px.
    let (k, _) = (first..=last)
        .map(|k| (k, p(k + 4) - p(k - 4)))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    let (hi, lo) = (p(k - LAG), p(k + LAG));
    if hi - lo < min_contrast {
        return None;
    }
    let mid = 0.5 * (hi + lo);
    // The crossing of `mid` nearest the steepest point.
    let mut best: Option<f64> = None;
    for j in (k - LAG)..(k + LAG) {
        if p(j) >= mid && p(j + 1) < mid {
            let t = (p(j) - mid) / (p(j) - p(j + 1));
            let at = (j as f64 + t) * STEP;
            if best.is_none_or(|b| (at - k as f64 * STEP).abs() < (b - k as f64 * STEP).abs()) {
                best = Some(at);
            }
        }
    }
    let d = best?;
    Some((x0 + dx * d, y0 + dy * d))
}

/// Edge points around `(x0, y0)`, searched between `from` and `to` pixels along `rays` rays.
fn edge_points(
    gray: &[u8],
    w: usize,
    h: usize,
    centre: (f64, f64),
    from: f64,
    to: f64,
    s: &CircleDetectorSettings,
) -> Vec<(f64, f64)> {
    let mut pts = Vec::with_capacity(s.rays);
    let mut profile = Vec::new();
    for i in 0..s.rays {
        let t = std::f64::consts::TAU * i as f64 / s.rays as f64;
        let ray = (t.cos(), t.sin());
        if let Some(p) = edge_on_ray(gray, w, h, centre, ray, from, to, s.min_contrast, &mut profile) {
            pts.push(p);
        }
    }
    pts
}

/// What the fitted ellipse's neighbourhood looks like (module doc, step 3).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Look {
    /// The two-level template's residual, relative to the contrast.
    residual: f64,
    /// Mean inside minus mean of the ring, codes.
    contrast: f64,
    /// Mean inside over mean of the ring.
    ratio: f64,
    /// Standard deviation inside, relative to the contrast.
    inside_spread: f64,
    /// Standard deviation over the ring, relative to the contrast.
    ring_spread: f64,
    /// Fraction of the perimeter with an edge across it.
    perimeter_edges: f64,
}

/// The fitted ellipse's neighbourhood (module doc, step 3): the levels,
/// spreads and residual of the best two-level elliptical template over
/// the ellipse and its ring to 1.5 times its size, leaving out a band of
/// a pixel either side of the edge (the lens's blur); then the fraction
/// of 64 points on the perimeter where the level 1.5 px inside exceeds
/// the level 1.5 px outside by half the contrast.
fn look(gray: &[u8], w: usize, h: usize, e: &Ellipse) -> Option<Look> {
    let reach = 1.5 * e.a + 2.0;
    let (x0, x1) = (
        (e.centre.0 - reach).floor().max(0.0) as usize,
        ((e.centre.0 + reach).ceil().max(0.0) as usize).min(w),
    );
    let (y0, y1) = (
        (e.centre.1 - reach).floor().max(0.0) as usize,
        ((e.centre.1 + reach).ceil().max(0.0) as usize).min(h),
    );
    let (s, c) = e.angle.sin_cos();
    // (count, sum, sum of squares) inside and over the ring.
    let (mut inside, mut ring) = ([0.0f64; 3], [0.0f64; 3]);
    let scale = e.b.max(1.0);
    for y in y0..y1 {
        for x in x0..x1 {
            let (px, py) = (x as f64 + 0.5 - e.centre.0, y as f64 + 0.5 - e.centre.1);
            let (u, v) = (c * px + s * py, -s * px + c * py);
            // The ellipse's "radius" at the pixel, and the pixel's distance from the edge.
            let rho = ((u / e.a).powi(2) + (v / e.b).powi(2)).sqrt();
            let value = f64::from(gray[y * w + x]);
            let acc = if (rho - 1.0) * scale < -1.0 {
                &mut inside
            } else if (rho - 1.0) * scale > 1.0 && rho <= 1.5 {
                &mut ring
            } else {
                continue;
            };
            acc[0] += 1.0;
            acc[1] += value;
            acc[2] += value * value;
        }
    }
    if inside[0] < 3.0 || ring[0] < 3.0 {
        return None;
    }
    let stats = |a: [f64; 3]| {
        let mean = a[1] / a[0];
        (mean, (a[2] / a[0] - mean * mean).max(0.0).sqrt(), a[2] - a[1] * mean)
    };
    let ((mi, si, ssd_i), (mr, sr, ssd_r)) = (stats(inside), stats(ring));
    let contrast = mi - mr;
    if contrast <= 0.0 {
        return None;
    }
    const ROUND: usize = 64;
    let edges = (0..ROUND)
        .filter(|k| {
            let t = std::f64::consts::TAU * *k as f64 / ROUND as f64;
            let (px, py) = e.point(t);
            // The outward normal: the conic's gradient direction.
            let (ct, st) = (t.cos(), t.sin());
            let (nu, nv) = (ct / e.a, st / e.b);
            let (nx, ny) = (c * nu - s * nv, s * nu + c * nv);
            let norm = nx.hypot(ny);
            let (nx, ny) = (nx / norm, ny / norm);
            let at = |d: f64| sample(gray, w, h, px + nx * d, py + ny * d);
            matches!((at(-1.5), at(1.5)), (Some(a), Some(b)) if a - b >= 0.5 * contrast)
        })
        .count();
    Some(Look {
        residual: (ssd_i + ssd_r) / ((inside[0] + ring[0]) * contrast * contrast),
        contrast,
        ratio: mi / mr.max(1.0),
        inside_spread: si / contrast,
        ring_spread: sr / contrast,
        perimeter_edges: edges as f64 / ROUND as f64,
    })
}

/// Verifies one candidate (module doc, step 2).
fn verify(gray: &[u8], w: usize, h: usize, c: &Candidate, s: &CircleDetectorSettings) -> Option<CircleDetection> {
    let floor = 0.35;
    let pts = edge_points(gray, w, h, (c.x, c.y), 0.3 * c.r, 2.0 * c.r, s);
    if (pts.len() as f64) < s.min_edge_fraction * s.rays as f64 {
        return None;
    }
    let fit = fit_ellipse_robust(&pts, floor)?;
    let e = fit.ellipse;
    if !(e.a.is_finite() && e.a < 3.0 * c.r && e.b > 0.3) {
        return None;
    }
    // Again from the fitted centre, searching around the fitted ellipse.
    let pts = edge_points(gray, w, h, e.centre, 0.5 * e.b, 1.5 * e.a + 1.0, s);
    if (pts.len() as f64) < s.min_edge_fraction * s.rays as f64 {
        return None;
    }
    let fit = fit_ellipse_robust(&pts, floor)?;
    let kept: Vec<(f64, f64)> = pts
        .iter()
        .zip(&fit.kept)
        .filter(|(_, k)| **k)
        .map(|(p, _)| *p)
        .collect();
    let e = fit.ellipse;
    if (kept.len() as f64) < s.min_edge_fraction * s.rays as f64
        || fit.rms > s.max_fit_rms_px
        || e.b / e.a < s.min_axis_ratio
        || e.a < 0.5 * s.min_radius_px
    {
        return None;
    }
    let l = look(gray, w, h, &e)?;
    if l.residual > s.max_template_residual
        || l.contrast < s.min_contrast
        || l.ratio < s.min_contrast_ratio
        || l.inside_spread > s.max_inside_spread
        || l.ring_spread > s.max_ring_spread
        || l.perimeter_edges < s.min_perimeter_edges
    {
        return None;
    }
    Some(CircleDetection {
        ellipse: e,
        edge_points: kept,
        fit_rms_px: fit.rms,
        template_residual: l.residual,
        contrast: l.contrast,
        contrast_ratio: l.ratio,
        inside_spread: l.inside_spread,
        ring_spread: l.ring_spread,
        perimeter_edges: l.perimeter_edges,
        ncc: c.ncc,
    })
}

/// The circle targets in an 8-bit gray photograph of `width` × `height`
/// (module doc), best template match first; an empty list for an image
/// too small to hold a template.
pub fn detect_circles(gray: &[u8], width: usize, height: usize, s: &CircleDetectorSettings) -> Vec<CircleDetection> {
    if width < 8 || height < 8 || gray.len() != width * height {
        return Vec::new();
    }
    let ii = Integral::new(gray, width, height);
    let candidates = sweep(&ii, width, height, s);
    drop(ii);
    // A candidate inside a circle already found is the same target.
    let seen = |found: &[CircleDetection], c: &Candidate| {
        found.iter().any(|d| {
            let e = &d.ellipse;
            (e.centre.0 - c.x).hypot(e.centre.1 - c.y) < e.a
        })
    };
    // In order of the template match, as if one by one: a batch of the
    // next candidates not yet seen is verified in parallel, then taken in
    // order, each checked again against the circles found before it.
    let batch = 2 * rayon::current_num_threads().max(1);
    let mut found: Vec<CircleDetection> = Vec::new();
    let mut next = 0;
    while next < candidates.len() {
        let mut todo: Vec<&Candidate> = Vec::with_capacity(batch);
        while next < candidates.len() && todo.len() < batch {
            if !seen(&found, &candidates[next]) {
                todo.push(&candidates[next]);
            }
            next += 1;
        }
        let verified: Vec<Option<CircleDetection>> =
            todo.par_iter().map(|c| verify(gray, width, height, c, s)).collect();
        for (c, d) in todo.into_iter().zip(verified) {
            let Some(d) = d else { continue };
            if seen(&found, c) {
                continue;
            }
            let e = d.ellipse;
            if found
                .iter()
                .all(|o| (o.ellipse.centre.0 - e.centre.0).hypot(o.ellipse.centre.1 - e.centre.1) > 0.5 * e.b)
            {
                found.push(d);
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A 400 × 300 image: a grey (110) background, dark (30) square plates
    /// with white (210) elliptical discs, 4 × 4 supersampled, noise σ 2.
    fn image(discs: &[Ellipse]) -> Vec<u8> {
        let (w, h) = (400usize, 300usize);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut out = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut sum = 0.0;
                for k in 0..16 {
                    let px = x as f64 + (f64::from(k % 4) + 0.5) / 4.0;
                    let py = y as f64 + (f64::from(k / 4) + 0.5) / 4.0;
                    let mut v = 110.0;
                    for e in discs {
                        let (s, c) = e.angle.sin_cos();
                        let (dx, dy) = (px - e.centre.0, py - e.centre.1);
                        let (u, vv) = (c * dx + s * dy, -s * dx + c * dy);
                        if u.abs() < 2.0 * e.a && vv.abs() < 2.0 * e.b {
                            v = if (u / e.a).powi(2) + (vv / e.b).powi(2) <= 1.0 {
                                210.0
                            } else {
                                30.0
                            };
                        }
                    }
                    sum += v;
                }
                let noise: f64 = (0..4).map(|_| rng.random::<f64>() - 0.5).sum::<f64>() * 2.0 * 3f64.sqrt();
                out[y * w + x] = (sum / 16.0 + noise).round().clamp(0.0, 255.0) as u8;
            }
        }
        out
    }

    #[test]
    fn discs_at_several_sizes_and_slants_are_found_to_a_twentieth_of_a_pixel() {
        let discs = [
            Ellipse {
                centre: (80.3, 70.6),
                a: 20.0,
                b: 19.0,
                angle: 0.2,
            },
            Ellipse {
                centre: (250.7, 90.2),
                a: 12.0,
                b: 6.0,
                angle: -0.9,
            },
            Ellipse {
                centre: (150.1, 210.4),
                a: 7.0,
                b: 5.5,
                angle: 1.2,
            },
            Ellipse {
                centre: (320.5, 220.5),
                a: 30.0,
                b: 14.0,
                angle: 0.0,
            },
        ];
        let img = image(&discs);
        let found = detect_circles(&img, 400, 300, &CircleDetectorSettings::default());
        assert_eq!(found.len(), discs.len(), "{found:#?}");
        for e in &discs {
            let d = found
                .iter()
                .min_by(|a, b| {
                    let da = (a.ellipse.centre.0 - e.centre.0).hypot(a.ellipse.centre.1 - e.centre.1);
                    let db = (b.ellipse.centre.0 - e.centre.0).hypot(b.ellipse.centre.1 - e.centre.1);
                    da.total_cmp(&db)
                })
                .expect("one");
            let f = d.ellipse;
            let off = (f.centre.0 - e.centre.0).hypot(f.centre.1 - e.centre.1);
            assert!(off < 0.05, "{e:?} found at {f:?}: {off} px off");
            assert!((f.a - e.a).abs() < 0.1 && (f.b - e.b).abs() < 0.1, "{e:?} vs {f:?}");
            assert!(d.fit_rms_px < 0.3 && d.template_residual < 0.2, "{d:?}");
        }
    }

    #[test]
    fn wrapped_integral_sums_are_exact_where_the_squares_pass_two_to_the_32() {
        // Bright codes (200-255) over 400 × 300: the squares sum to about
        // 7e9 over the image, past 2³², so the prefix sums wrap.
        let (w, h) = (400usize, 300usize);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let gray: Vec<u8> = (0..w * h).map(|_| rng.random_range(200..=255u8)).collect();
        let ii = Integral::new(&gray, w, h);
        let brute = |x0: usize, y0: usize, x1: usize, y1: usize| {
            let (mut sum, mut sq) = (0u64, 0u64);
            for y in y0..y1 {
                for x in x0..x1 {
                    let v = u64::from(gray[y * w + x]);
                    sum += v;
                    sq += v * v;
                }
            }
            (sum, sq)
        };
        let mut rects = vec![(0, 0, w, h), (3, 5, w, h), (0, 0, 1, 1), (17, 250, 399, 300)];
        for _ in 0..200 {
            let (x0, y0) = (rng.random_range(0..w), rng.random_range(0..h));
            rects.push((x0, y0, rng.random_range(x0 + 1..=w), rng.random_range(y0 + 1..=h)));
        }
        for (x0, y0, x1, y1) in rects {
            let (sum, sq) = brute(x0, y0, x1, y1);
            let mut col = vec![0u32; w + 1];
            ii.column_sums(y0, y1, &mut col);
            assert_eq!(u64::from(col[x1].wrapping_sub(col[x0])), sum, "{x0} {y0} {x1} {y1}");
            let strip = sq_strip_rows(x1 - x0);
            assert_eq!(ii.sq(x0, y0, x1, y1, strip), sq, "{x0} {y0} {x1} {y1}");
        }
        // The whole image's squares (7e9) need more than one strip.
        assert!(brute(0, 0, w, h).1 > u64::from(u32::MAX) && sq_strip_rows(w) < h);
    }

    #[test]
    fn a_plain_image_and_a_dark_disc_give_nothing() {
        let mut img = vec![120u8; 400 * 300];
        // A dark disc on a light background is not a target.
        for y in 0..300usize {
            for x in 0..400usize {
                if (x as f64 - 200.0).hypot(y as f64 - 150.0) < 20.0 {
                    img[y * 400 + x] = 20;
                }
            }
        }
        assert!(detect_circles(&img, 400, 300, &CircleDetectorSettings::default()).is_empty());
    }
}
