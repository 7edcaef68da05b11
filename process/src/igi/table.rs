//! The result as the thesis's Table 4.1 prints it: per surface, the true
//! parameters, the recovered ones and the error in percent (γ: in
//! degrees), with the thesis's own errors beside ours when given.

use std::fmt::Write;

use super::recover::{IgiResult, SurfaceResult, canonical_lobe};
use crate::brdf::{WardLobe, WardMaterial};

/// The errors (percent) Table 4.1 of the thesis reports for its six
/// surfaces, as (ρd, ρs, αx, αy); `None` where the table has none.
pub const THESIS_TABLE_4_1_ERRORS_PCT: [[Option<f64>; 4]; 6] = [
    [Some(6.10), Some(2.34), Some(0.71), Some(1.73)],
    [Some(7.36), Some(3.02), Some(0.06), None],
    [Some(0.88), Some(4.77), Some(1.36), None],
    [Some(0.59), Some(8.90), Some(1.55), None],
    [Some(3.16), Some(1.09), Some(0.58), None],
    [Some(4.67), Some(3.08), Some(1.73), Some(1.91)],
];

/// The representation of `lobe` ((αx, αy, γ) ≡ (αy, αx, γ + 90°) ≡
/// (αx, αy, γ + 180°)) whose γ is nearest `gamma_rad`.
pub fn nearest_representation(lobe: &WardLobe, gamma_rad: f64) -> WardLobe {
    let half = std::f64::consts::FRAC_PI_2;
    let mut best = *lobe;
    let mut best_d = f64::INFINITY;
    for k in -4i32..=4 {
        let mut l = *lobe;
        l.gamma_rad = lobe.gamma_rad + f64::from(k) * half;
        if k.rem_euclid(2) == 1 {
            std::mem::swap(&mut l.alpha_x, &mut l.alpha_y);
        }
        let d = (l.gamma_rad - gamma_rad).abs();
        if d < best_d {
            best_d = d;
            best = l;
        }
    }
    best
}

/// The parameters (ρd, ρs, αx, αy, γ in degrees) of a material in channel
/// 0 (the thesis's surfaces are grey), in the representation nearest
/// `gamma_rad`, or in the canonical one (αx ≥ αy, γ in (−90°, 90°],
/// [`canonical_lobe`]) when there is no γ to match.
fn params(m: &WardMaterial, gamma_rad: Option<f64>) -> [Option<f64>; 5] {
    match m.lobe {
        None => [Some(m.rho_d[0]), Some(0.0), None, None, None],
        Some(l) => {
            let l = match gamma_rad {
                Some(g) => nearest_representation(&l, g),
                None => canonical_lobe(l),
            };
            [
                Some(m.rho_d[0]),
                Some(l.rho_s[0]),
                Some(l.alpha_x),
                Some(l.alpha_y),
                Some(l.gamma_rad.to_degrees()),
            ]
        }
    }
}

/// The relative errors (percent) of ρd, ρs, αx, αy and the absolute error
/// of γ (degrees) of `recovered` against `truth`, in the representation
/// nearest the truth's γ; `None` where a parameter is missing on either side.
pub fn errors(recovered: &WardMaterial, truth: &WardMaterial) -> [Option<f64>; 5] {
    let g = truth.lobe.map_or(0.0, |l| l.gamma_rad);
    let (r, t) = (params(recovered, Some(g)), params(truth, Some(g)));
    let mut e = [None; 5];
    for k in 0..5 {
        if let (Some(a), Some(b)) = (r[k], t[k]) {
            e[k] = Some(if k == 4 {
                (a - b).abs()
            } else if b != 0.0 {
                100.0 * (a - b).abs() / b
            } else {
                100.0 * a.abs()
            });
        }
    }
    e
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".to_string(), |v| format!("{v:.digits$}"))
}

/// Table 4.1's layout: for each surface, rows "True" (when `truth` has
/// it), "Recovered", "Error(%)" (γ in degrees) and, when `thesis` has the
/// row, "Thesis(%)"; then the model chosen and why. Anisotropic surfaces
/// are shown in the representation nearest the true γ, or without a true
/// lobe in the canonical one (αx ≥ αy, γ in (−90°, 90°]), as
/// `materials.json` gives them.
pub fn format_table(result: &IgiResult, truth: &[Option<WardMaterial>], thesis: Option<&[[Option<f64>; 4]]>) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<10} {:<10} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "surface", "", "rho_d", "rho_s", "alpha_x", "alpha_y", "gamma(deg)"
    );
    let row = |s: &mut String, name: &str, label: &str, v: [Option<f64>; 5], d: usize| {
        let _ = writeln!(
            s,
            "{:<10} {:<10} {:>10} {:>10} {:>10} {:>10} {:>10}",
            name,
            label,
            cell(v[0], d),
            cell(v[1], d),
            cell(v[2], d),
            cell(v[3], d),
            cell(v[4], if d > 2 { 3 } else { d })
        );
    };
    for (i, r) in result.surfaces.iter().enumerate() {
        let t = truth.get(i).copied().flatten();
        let g = t.and_then(|t| t.lobe).map(|l| l.gamma_rad);
        if let Some(t) = &t {
            row(&mut s, &r.name, "True", params(t, g), 4);
        }
        let name = if t.is_some() { "" } else { r.name.as_str() };
        match &r.material {
            Some(m) => row(&mut s, name, "Recovered", params(m, g), 6),
            None => {
                let _ = writeln!(s, "{:<10} {:<10} (nothing recovered)", name, "Recovered");
            }
        }
        if let (Some(m), Some(t)) = (&r.material, &t) {
            row(&mut s, "", "Error(%)", errors(m, t), 2);
        }
        if let Some(th) = thesis.and_then(|th| th.get(i)) {
            row(&mut s, "", "Thesis(%)", [th[0], th[1], th[2], th[3], None], 2);
        }
        let _ = writeln!(s, "{:<10} {}", "", describe(r));
    }
    let _ = writeln!(
        s,
        "Ward normalization: {}; {} ΔS iteration(s); {:.2} s",
        result.variant,
        result.iterations.len(),
        result.seconds
    );
    s
}

/// One line: the model, plastic or metal, the energy check and the reason.
fn describe(r: &SurfaceResult) -> String {
    format!(
        "{:?}, {:?}, directional albedo {:.3} (0°) / {:.3} (60°){}: {}",
        r.model,
        r.kind,
        r.directional_albedo[0],
        r.directional_albedo[1],
        if r.energy_ok { "" } else { " EXCEEDS 1" },
        r.reason
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::WardVariant;

    /// Without a truth to match, the table prints the canonical form that
    /// materials.json gives (it printed (0.05, 0.287, 44.9°) for a brushed
    /// board whose materials.json said (0.287, 0.05, −45.1°)).
    #[test]
    fn without_a_truth_the_table_prints_the_canonical_form() {
        let m = WardMaterial {
            rho_d: [0.17; 3],
            lobe: Some(WardLobe::new([0.1; 3], 0.05, 0.287, 44.9f64.to_radians(), WardVariant::Ward1992).unwrap()),
        };
        let p = params(&m, None);
        assert_eq!(p[2], Some(0.287));
        assert_eq!(p[3], Some(0.05));
        assert!((p[4].unwrap() - (-45.1)).abs() < 1e-9, "{p:?}");
    }

    #[test]
    fn the_swapped_representation_is_matched_to_the_truth() {
        let truth = WardMaterial {
            rho_d: [0.3; 3],
            lobe: Some(WardLobe::new([0.08; 3], 0.6, 0.03, 0.0, WardVariant::Ward1992).unwrap()),
        };
        // (0.03, 0.6, 89.9°) is (0.6, 0.03, −0.1°).
        let rec = WardMaterial {
            rho_d: [0.303; 3],
            lobe: Some(WardLobe::new([0.08; 3], 0.0303, 0.6, 89.9f64.to_radians(), WardVariant::Ward1992).unwrap()),
        };
        let e = errors(&rec, &truth);
        assert!((e[0].unwrap() - 1.0).abs() < 1e-9);
        assert!(e[1].unwrap().abs() < 1e-9);
        assert!(e[2].unwrap().abs() < 1e-9);
        assert!((e[3].unwrap() - 1.0).abs() < 1e-9);
        assert!((e[4].unwrap() - 0.1).abs() < 1e-9);
    }
}
