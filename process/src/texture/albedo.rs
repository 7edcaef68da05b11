//! Albedo textures from the recovered pseudo-albedos (thesis §5.4, eqs.
//! 5.11–5.12: ρ^se and ρ^sun per surface-grid cell), laid out as the
//! radiance textures are (§3.4): one patch per face, packed into atlas
//! pages, exported as OBJ + MTL + EXR/PNG.
//!
//! The products are a [`Reflectance`]: the surface grid (square cells of
//! `spacing_m` over each face's planar texture coordinates) and each
//! cell's pseudo-albedos, as `campanile process` and `campanile outdoor
//! recover` write them (`albedo/materials.ron` with its atlases, read by
//! [`crate::outdoor::atlas::read_materials`]). Each texel of a patch is the
//! mean of the cells under `n × n` points spread over it (`n =
//! ⌈2 Δ / spacing⌉` within [2, 8], `Δ` the texel side), so a texel larger
//! than a cell averages the cells it covers and a smaller one takes its
//! cell's value. With the patches on the grid's lattice
//! ([`super::patch::patches_on_lattice`]) at the grid's spacing, each texel
//! is exactly one grid square.
//!
//! Cells no photograph saw hold their nearest seen neighbours' median in
//! the products, not a measurement: a texel whose points all fall on such
//! cells (or on no cell) is counted unseen and filled from its neighbours
//! ([`super::fill`]), as radiance texels no photograph sees are; the
//! verdict follows the seen fraction ([`judge_albedo`]).

use super::TextureError;
use super::fill::fill_patch;
use super::patch::{Patch, inside};
use super::seam::{Quality, QualityLimits, SeamFigures};
use super::synthesis::{PatchTexture, Synthesis, SynthesisReport, TexelStatus};
use crate::outdoor::{CellStatus, Reflectance};
use crate::render::Scene;

/// Which pseudo-albedo to texture with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PseudoAlbedo {
    /// ρ^se: the pseudo-albedo for the sky's and environment's spectrum (eq. 5.11).
    SkyEnvironment,
    /// ρ^sun: the pseudo-albedo for the sun's spectrum (eq. 5.12).
    Sun,
}

/// Sub-samples per texel side for texels of `texel_m` on cells of `spacing_m`.
pub fn subsamples(texel_m: f64, spacing_m: f64) -> usize {
    ((2.0 * texel_m / spacing_m).ceil() as usize).clamp(2, 8)
}

/// The albedo texture of each of `patches` from `refl` (module doc).
/// Refused when a patch's surface is not among the products' surfaces.
/// `step` is called after each patch.
pub fn albedo_synthesis(
    scene: &Scene,
    patches: &[Patch],
    refl: &Reflectance,
    which: PseudoAlbedo,
    step: &dyn Fn(),
) -> Result<Synthesis, TextureError> {
    let grid = &refl.grid;
    if refl.cells.len() != grid.cells.len() {
        return Err(TextureError::BadSetting {
            field: "reflectance",
            value: format!("{} cell estimates", refl.cells.len()),
            expected: format!("one per grid cell ({})", grid.cells.len()),
        });
    }
    for p in patches {
        if !grid.targets.contains(&p.surface) {
            let covered: Vec<&str> = grid.targets.iter().map(|&s| scene.surfaces()[s].as_str()).collect();
            return Err(TextureError::NotInProducts {
                name: scene.surfaces()[p.surface].clone(),
                covered: covered.join(", "),
            });
        }
    }
    Ok(resample(
        scene,
        patches,
        |patch| subsamples(patch.texel_m, grid.spacing_m),
        |tri, p| {
            let cell = grid
                .cell_at(scene, tri, p)
                .or_else(|| grid.nearest_cell(scene, tri, p))?;
            let est = &refl.cells[cell];
            if est.status == CellStatus::Unseen {
                return None;
            }
            let rho = match which {
                PseudoAlbedo::SkyEnvironment => est.rho_se,
                PseudoAlbedo::Sun => est.rho_sun,
            };
            rho.iter().all(|v| v.is_finite()).then_some(SubSample::Seen(rho))
        },
        step,
    ))
}

/// What one sub-sample of a texel reads from the products.
pub(crate) enum SubSample {
    /// A measured albedo (a cell or map texel a view saw).
    Seen([f64; 3]),
    /// The products' own fill where nothing was seen.
    Unseen([f64; 3]),
}

/// Resamples every on-face texel of `patches` at `n × n` points
/// (`n = subsamples_of(patch)`), each read by `lookup(triangle, point)`:
/// a texel is the mean of its `Seen` points, or, with none, unseen and
/// filled from its neighbours ([`super::fill`]). A patch with no seen
/// texel at all keeps the mean of its texels' `Unseen` points (the
/// products' own fill) instead. `step` is called after each patch.
pub(crate) fn resample(
    scene: &Scene,
    patches: &[Patch],
    subsamples_of: impl Fn(&Patch) -> usize,
    lookup: impl Fn(usize, &nalgebra::Vector3<f64>) -> Option<SubSample>,
    step: &dyn Fn(),
) -> Synthesis {
    let tris = scene.triangles();
    let mut report = SynthesisReport {
        used: vec![0],
        occluded: vec![0],
        grazing: vec![0],
        ..Default::default()
    };
    let mut textures = Vec::with_capacity(patches.len());
    for patch in patches {
        let n = subsamples_of(patch);
        let size = patch.cols * patch.rows;
        let mut tex = PatchTexture {
            rgb: vec![[0.0; 3]; size],
            weight: vec![0.0; size],
            status: vec![TexelStatus::Padding; size],
            photos: vec![0; size],
            spread: vec![0.0; size],
        };
        // The products' own values of the texels nothing saw.
        let mut own: Vec<Option<[f32; 3]>> = vec![None; size];
        let (mut on_face, mut unseen) = (0usize, 0usize);
        for j in 0..patch.rows {
            for i in 0..patch.cols {
                let idx = j * patch.cols + i;
                if patch.texel_triangle[idx].is_none() {
                    continue;
                }
                on_face += 1;
                let (mut seen_sum, mut seen) = ([0.0f64; 3], 0usize);
                let (mut other_sum, mut other) = ([0.0f64; 3], 0usize);
                for a in 0..n {
                    for b in 0..n {
                        let s = patch.origin[0] + (i as f64 + (a as f64 + 0.5) / n as f64) * patch.texel_m;
                        let t = patch.origin[1] + (j as f64 + (b as f64 + 0.5) / n as f64) * patch.texel_m;
                        let p = patch.point_at(s, t);
                        let Some(&tri) = patch.triangles.iter().find(|&&k| inside(&tris[k], &p)) else {
                            continue;
                        };
                        let (v, sum, count) = match lookup(tri, &p) {
                            Some(SubSample::Seen(v)) => (v, &mut seen_sum, &mut seen),
                            Some(SubSample::Unseen(v)) => (v, &mut other_sum, &mut other),
                            None => continue,
                        };
                        (0..3).for_each(|c| sum[c] += v[c]);
                        *count += 1;
                    }
                }
                if seen > 0 {
                    tex.rgb[idx] = seen_sum.map(|v| (v / seen as f64) as f32);
                    tex.weight[idx] = seen as f32 / (n * n) as f32;
                    tex.status[idx] = TexelStatus::Seen;
                    tex.photos[idx] = 1;
                    report.used[0] += 1;
                } else {
                    tex.status[idx] = TexelStatus::Filled;
                    unseen += 1;
                    if other > 0 {
                        own[idx] = Some(other_sum.map(|v| (v / other as f64) as f32));
                    }
                }
            }
        }
        let none_seen = !tex.status.contains(&TexelStatus::Seen);
        fill_patch(&mut tex, patch.cols, patch.rows);
        if none_seen {
            keep_own_fill(&mut tex, &own);
        }
        report.texels_on_faces += on_face;
        report.unseen += unseen;
        report.per_patch.push((on_face, unseen));
        textures.push(tex);
        step();
    }
    Synthesis { textures, report }
}

/// A patch nothing saw: its on-face texels take the products' own values
/// (`own`), the padding their mean.
fn keep_own_fill(tex: &mut PatchTexture, own: &[Option<[f32; 3]>]) {
    let (mut sum, mut count) = ([0.0f64; 3], 0usize);
    for (rgb, o) in tex.rgb.iter_mut().zip(own) {
        if let Some(v) = o {
            *rgb = *v;
            (0..3).for_each(|c| sum[c] += f64::from(v[c]));
            count += 1;
        }
    }
    if count == 0 {
        return;
    }
    let mean = sum.map(|v| (v / count as f64) as f32);
    for (rgb, s) in tex.rgb.iter_mut().zip(&tex.status) {
        if *s == TexelStatus::Padding {
            *rgb = mean;
        }
    }
}

/// What an albedo texture's texels are resampled from, for the verdict's wording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlbedoSource {
    /// The pseudo-albedo products' surface-grid cells (this module).
    ProductCells,
    /// The texels of inverse global illumination's albedo maps ([`super::igi_albedo`]).
    IgiMapTexels,
}

impl AlbedoSource {
    fn none_seen(self) -> &'static str {
        match self {
            AlbedoSource::ProductCells => {
                "no texel lies on a cell that a photograph saw: the products hold no measured albedo here"
            }
            AlbedoSource::IgiMapTexels => {
                "no texel lies on a map texel that a view saw: the maps hold no measured albedo here"
            }
        }
    }

    fn unseen(self) -> &'static str {
        match self {
            AlbedoSource::ProductCells => "cells no photograph saw",
            AlbedoSource::IgiMapTexels => "map texels no view saw",
        }
    }
}

/// The verdict on an albedo texture: `failed` when no texel or less than
/// [`QualityLimits::min_coverage_poor`] of them lie on cells a photograph
/// saw, `poor` below [`QualityLimits::min_coverage_ok`], else `ok` (there
/// are no photographs to disagree at seams: the seam figures are empty).
pub fn judge_albedo(report: &SynthesisReport, limits: &QualityLimits) -> Quality {
    judge_albedo_from(report, limits, AlbedoSource::ProductCells)
}

/// [`judge_albedo`] on texels resampled from `source` (the reasons name it).
pub fn judge_albedo_from(report: &SynthesisReport, limits: &QualityLimits, source: AlbedoSource) -> Quality {
    let coverage = report.coverage();
    let mut reasons = Vec::new();
    let seen = report.texels_on_faces - report.unseen;
    let verdict = if seen == 0 {
        reasons.push(source.none_seen().into());
        "failed"
    } else if coverage < limits.min_coverage_poor {
        reasons.push(format!(
            "coverage {:.1}% below {:.0}%: {} texels lie on {}",
            100.0 * coverage,
            100.0 * limits.min_coverage_poor,
            report.unseen,
            source.unseen()
        ));
        "failed"
    } else if coverage < limits.min_coverage_ok {
        reasons.push(format!(
            "coverage {:.1}% below {:.0}%: {} texels on {} were filled from their neighbours",
            100.0 * coverage,
            100.0 * limits.min_coverage_ok,
            report.unseen,
            source.unseen()
        ));
        "poor"
    } else {
        "ok"
    };
    Quality {
        verdict: verdict.to_string(),
        coverage,
        texels_on_faces: report.texels_on_faces,
        unseen: report.unseen,
        seams: SeamFigures::default(),
        reasons,
        limits: *limits,
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::outdoor::observation::SamplingReport;
    use crate::outdoor::{CellEstimate, Grid};
    use crate::render::{Material, Triangle};
    use crate::texture::patch::{patches, patches_on_lattice};

    /// A 4 m × 2 m wall (s = x, t = z) on a 0.5 m grid whose cell (i, j)
    /// holds ρ^se = 0.1 + 0.01 i + 0.1 j, ρ^sun twice that, and whose
    /// column i = 7 no photograph saw.
    fn wall() -> (Scene, Reflectance) {
        let v = |x: f64, z: f64| Vector3::new(x, 0.0, z);
        let tris = vec![
            Triangle::new([v(0.0, 0.0), v(4.0, 0.0), v(4.0, 2.0)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0), v(4.0, 2.0), v(0.0, 2.0)], 0, 0).unwrap(),
            Triangle::new([v(5.0, 0.0), v(6.0, 0.0), v(6.0, 1.0)], 0, 1).unwrap(),
        ];
        let scene = Scene::new(
            tris,
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["wall".into(), "shed".into()],
        )
        .unwrap();
        let grid = Grid::new(&scene, &[0], 0.5, &[Vector3::new(2.0, -10.0, 1.0)]).unwrap();
        let cells = grid
            .cells
            .iter()
            .map(|c| {
                let (i, j) = (c.lattice.0 as f64, c.lattice.1 as f64);
                let se = 0.1 + 0.01 * i + 0.1 * j;
                CellEstimate {
                    rho_se: [se; 3],
                    rho_sun: [2.0 * se; 3],
                    sigma_sun: [0.0; 3],
                    sigma_se: [0.0; 3],
                    status: if c.lattice.0 == 7 {
                        CellStatus::Unseen
                    } else {
                        CellStatus::Solved
                    },
                    condition: 1.0,
                    amplification: 1.0,
                    observations: 2,
                    rms_relative: 0.0,
                }
            })
            .collect();
        let refl = Reflectance {
            face_ratio: vec![[1.0; 3]; grid.faces.len()],
            grid,
            cells,
            photos: Vec::new(),
            sampling: SamplingReport::default(),
            diagnostics: Vec::new(),
        };
        (scene, refl)
    }

    /// On the grid's lattice at its spacing, every texel is its cell: the
    /// seen ones exactly (to f32), the unseen column (4 texels of 32)
    /// counted and filled from column 6; a verdict of `poor` (87.5%).
    /// At half the spacing each texel takes its cell; at twice, the mean
    /// of its four cells.
    #[test]
    fn texels_copy_their_cells_and_unseen_cells_are_reported() {
        let (scene, refl) = wall();
        let wall = ["wall".to_string()];
        let ps = patches_on_lattice(&scene, Some(&wall), 0.5, 10_000).unwrap();
        assert_eq!((ps[0].cols, ps[0].rows), (8, 4));
        let syn = albedo_synthesis(&scene, &ps, &refl, PseudoAlbedo::SkyEnvironment, &|| {}).unwrap();
        let r = &syn.report;
        assert_eq!((r.texels_on_faces, r.unseen), (32, 4));
        let tex = &syn.textures[0];
        for j in 0..4 {
            for i in 0..8 {
                let k = j * 8 + i;
                let want = 0.1 + 0.01 * i.min(6) as f64 + 0.1 * j as f64;
                if i == 7 {
                    assert_eq!(tex.status[k], TexelStatus::Filled);
                    // Filled from column 6 (rows j−1..j+1 of it): within 0.1 of its row's value.
                    assert!(
                        (f64::from(tex.rgb[k][0]) - want).abs() <= 0.1 + 1e-6,
                        "{:?}",
                        tex.rgb[k]
                    );
                } else {
                    assert_eq!(tex.status[k], TexelStatus::Seen);
                    assert!(
                        (f64::from(tex.rgb[k][0]) - want).abs() < 1e-6,
                        "({i}, {j}): {:?}",
                        tex.rgb[k]
                    );
                }
            }
        }
        let q = judge_albedo(r, &QualityLimits::default());
        assert_eq!(q.verdict, "poor");
        assert!(q.reasons[0].contains("87.5%"), "{:?}", q.reasons);
        // ρ^sun is twice ρ^se.
        let sun = albedo_synthesis(&scene, &ps, &refl, PseudoAlbedo::Sun, &|| {}).unwrap();
        assert!((sun.textures[0].rgb[9][1] - 2.0 * tex.rgb[9][1]).abs() < 1e-6);
        // Half the spacing: texel (3, 5) lies in cell (1, 2).
        let fine = patches_on_lattice(&scene, Some(&wall), 0.25, 10_000).unwrap();
        let f = albedo_synthesis(&scene, &fine, &refl, PseudoAlbedo::SkyEnvironment, &|| {}).unwrap();
        let v = f64::from(f.textures[0].rgb[5 * fine[0].cols + 3][0]);
        assert!((v - (0.1 + 0.01 + 0.2)).abs() < 1e-6, "{v}");
        // Twice the spacing: texel (1, 0) covers cells i 2–3, j 0–1: mean 0.1 + 0.025 + 0.05.
        let coarse = patches_on_lattice(&scene, Some(&wall), 1.0, 10_000).unwrap();
        let c = albedo_synthesis(&scene, &coarse, &refl, PseudoAlbedo::SkyEnvironment, &|| {}).unwrap();
        let v = f64::from(c.textures[0].rgb[1][0]);
        assert!((v - 0.175).abs() < 1e-6, "{v}");
        // A surface the products do not cover is refused by name.
        let all = patches(&scene, None, 0.5, 10_000).unwrap();
        let err = albedo_synthesis(&scene, &all, &refl, PseudoAlbedo::SkyEnvironment, &|| {})
            .unwrap_err()
            .to_string();
        assert!(err.contains("\"shed\"") && err.contains("cover: wall"), "{err}");
    }
}
