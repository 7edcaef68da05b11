//! The patches packed into atlas pages with texture coordinates (thesis
//! §3.4: "place the synthetic texture patches into texture maps, and
//! therefore obtain texture coordinates"). The packing is the
//! `rectangle-pack` crate's (largest first into free rectangles, the best
//! fit by volume), into square power-of-two pages: the smallest page that
//! holds every patch, up to [`AtlasSettings::max_page`], then more pages.
//!
//! Each patch sits in its page with a gutter of [`AtlasSettings::gutter`]
//! texels copied from its edge, so a bilinear lookup near a patch border
//! (Blender's default, unlike the thesis's `GL_NEAREST`) never reads a
//! neighbouring patch. Patch texel `(i, j)` is page pixel
//! `(x + g + i, y + g + rows − 1 − j)`: `t`, up the face, is up in the image.

use std::collections::BTreeMap;

use nalgebra::Vector3;
use rectangle_pack::{
    GroupedRectsToPlace, RectToInsert, TargetBin, contains_smallest_box, pack_rects, volume_heuristic,
};

use super::TextureError;
use super::patch::Patch;
use super::synthesis::PatchTexture;
use crate::render::Scene;

/// The knobs of packing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AtlasSettings {
    /// Texels copied around each patch.
    pub gutter: usize,
    /// Largest page side, texels.
    pub max_page: usize,
}

impl Default for AtlasSettings {
    fn default() -> Self {
        AtlasSettings {
            gutter: 2,
            max_page: 4096,
        }
    }
}

/// One atlas image.
#[derive(Debug, Clone, PartialEq)]
pub struct Page {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// Linear RGB, interleaved, top row first.
    pub rgb: Vec<f32>,
}

/// Where a patch sits: its page and the top-left corner of its rectangle
/// (gutter included).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Placement {
    /// The page.
    pub page: usize,
    /// Left column.
    pub x: usize,
    /// Top row.
    pub y: usize,
}

/// The packed atlas.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// The pages.
    pub pages: Vec<Page>,
    /// Per patch, in the patches' order.
    pub placements: Vec<Placement>,
    /// The gutter used.
    pub gutter: usize,
}

impl Atlas {
    /// The page pixel (continuous, from the page's top-left corner) of
    /// world point `p` on `patch` (number `k`).
    pub fn pixel(&self, patch: &Patch, k: usize, p: &Vector3<f64>) -> [f64; 2] {
        let [li, lj] = patch.lattice(p);
        let pl = self.placements[k];
        let g = self.gutter as f64;
        [pl.x as f64 + g + li, pl.y as f64 + g + patch.rows as f64 - lj]
    }

    /// OBJ texture coordinates `(u, v)` (v up from the image's bottom) of
    /// world point `p` on `patch` (number `k`).
    pub fn uv(&self, patch: &Patch, k: usize, p: &Vector3<f64>) -> [f64; 2] {
        let [x, y] = self.pixel(patch, k, p);
        let page = &self.pages[self.placements[k].page];
        [x / page.width as f64, 1.0 - y / page.height as f64]
    }

    /// Bilinear lookup of page `page` at continuous pixel `(x, y)`, clamped
    /// at the page's edges (what a renderer does with the texture).
    pub fn lookup(&self, page: usize, x: f64, y: f64) -> [f64; 3] {
        let pg = &self.pages[page];
        let (fx, fy) = (x - 0.5, y - 0.5);
        let x0 = fx.floor();
        let y0 = fy.floor();
        let (ax, ay) = (fx - x0, fy - y0);
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        let (xa, xb) = (clamp(x0, pg.width), clamp(x0 + 1.0, pg.width));
        let (ya, yb) = (clamp(y0, pg.height), clamp(y0 + 1.0, pg.height));
        let at = |xx: usize, yy: usize, c: usize| f64::from(pg.rgb[(yy * pg.width + xx) * 3 + c]);
        [0, 1, 2].map(|c| {
            (at(xa, ya, c) * (1.0 - ax) + at(xb, ya, c) * ax) * (1.0 - ay)
                + (at(xa, yb, c) * (1.0 - ax) + at(xb, yb, c) * ax) * ay
        })
    }

    /// Total texels over all pages.
    pub fn texels(&self) -> usize {
        self.pages.iter().map(|p| p.width * p.height).sum()
    }
}

/// Packs `patches` with their `textures` into pages (module doc); `scene`
/// names the surfaces in errors.
pub fn pack(
    scene: &Scene,
    patches: &[Patch],
    textures: &[PatchTexture],
    settings: &AtlasSettings,
) -> Result<Atlas, TextureError> {
    let g = settings.gutter;
    let sizes: Vec<(usize, usize)> = patches.iter().map(|p| (p.cols + 2 * g, p.rows + 2 * g)).collect();
    for (p, &(w, h)) in patches.iter().zip(&sizes) {
        if w > settings.max_page || h > settings.max_page {
            return Err(TextureError::PatchTooLarge {
                surface: scene.surfaces()[p.surface].clone(),
                width: w,
                height: h,
                page: settings.max_page,
            });
        }
    }
    let mut rects = GroupedRectsToPlace::<usize, ()>::new();
    for (k, &(w, h)) in sizes.iter().enumerate() {
        rects.push_rect(k, None, RectToInsert::new(w as u32, h as u32, 1));
    }
    let area: usize = sizes.iter().map(|(w, h)| w * h).sum();
    let largest = sizes.iter().map(|&(w, h)| w.max(h)).max().unwrap_or(1);
    let mut start = largest.max((area as f64).sqrt().ceil() as usize).next_power_of_two();
    start = start.min(settings.max_page.next_power_of_two());
    let mut found = None;
    'pages: for n in 1..=patches.len().max(1) {
        let mut side = start;
        while side <= settings.max_page.max(start) {
            let mut bins = BTreeMap::new();
            for b in 0..n {
                bins.insert(b, TargetBin::new(side as u32, side as u32, 1));
            }
            if let Ok(placed) = pack_rects(&rects, &mut bins, &volume_heuristic, &contains_smallest_box) {
                let mut placements = vec![Placement { page: 0, x: 0, y: 0 }; patches.len()];
                for (k, (bin, loc)) in placed.packed_locations() {
                    placements[*k] = Placement {
                        page: *bin,
                        x: loc.x() as usize,
                        y: loc.y() as usize,
                    };
                }
                found = Some((n, side, placements));
                break 'pages;
            }
            side *= 2;
        }
        start = settings.max_page;
    }
    let (n, side, placements) = found.ok_or_else(|| TextureError::BadSetting {
        field: "max_page",
        value: settings.max_page.to_string(),
        expected: "pages large enough to pack the patches".into(),
    })?;
    let mut pages: Vec<Page> = (0..n)
        .map(|_| Page {
            width: side,
            height: side,
            rgb: vec![0.0; side * side * 3],
        })
        .collect();
    for ((patch, tex), pl) in patches.iter().zip(textures).zip(&placements) {
        let page = &mut pages[pl.page];
        let (w, h) = (patch.cols + 2 * g, patch.rows + 2 * g);
        for yy in 0..h {
            for xx in 0..w {
                // The patch texel this page pixel copies (the nearest one in the gutter).
                let i = (xx as i64 - g as i64).clamp(0, patch.cols as i64 - 1) as usize;
                let row = (yy as i64 - g as i64).clamp(0, patch.rows as i64 - 1) as usize;
                let j = patch.rows - 1 - row;
                let v = tex.rgb[j * patch.cols + i];
                let o = ((pl.y + yy) * page.width + pl.x + xx) * 3;
                page.rgb[o..o + 3].copy_from_slice(&v);
            }
        }
    }
    Ok(Atlas {
        pages,
        placements,
        gutter: g,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Material, Triangle};
    use crate::texture::patch::patches;
    use crate::texture::synthesis::TexelStatus;

    /// Three walls packed: no two rectangles overlap, every patch lies in
    /// its page, and each texel centre's texture coordinates land on the
    /// page pixel holding that texel's value.
    #[test]
    fn packed_patches_do_not_overlap_and_uvs_hit_their_texels() {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let mut tris = Vec::new();
        for (s, (w, h)) in [(6.0, 3.0), (2.0, 5.0), (4.0, 4.0)].iter().enumerate() {
            let y = s as f64 * 10.0;
            tris.push(Triangle::new([v(0.0, y, 0.0), v(*w, y, 0.0), v(*w, y, *h)], 0, s as u32).unwrap());
            tris.push(Triangle::new([v(0.0, y, 0.0), v(*w, y, *h), v(0.0, y, *h)], 0, s as u32).unwrap());
        }
        let scene = Scene::new(
            tris,
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["a".into(), "b".into(), "c".into()],
        )
        .unwrap();
        let ps = patches(&scene, None, 0.1, 1_000_000).unwrap();
        // Each texel's value encodes (patch, i, j).
        let textures: Vec<PatchTexture> = ps
            .iter()
            .enumerate()
            .map(|(k, p)| PatchTexture {
                rgb: (0..p.rows)
                    .flat_map(|j| (0..p.cols).map(move |i| [k as f32, i as f32, j as f32]))
                    .collect(),
                weight: vec![1.0; p.cols * p.rows],
                status: vec![TexelStatus::Seen; p.cols * p.rows],
                photos: vec![1; p.cols * p.rows],
                spread: vec![0.0; p.cols * p.rows],
            })
            .collect();
        let atlas = pack(&scene, &ps, &textures, &AtlasSettings::default()).unwrap();
        assert_eq!(atlas.pages.len(), 1);
        let side = atlas.pages[0].width;
        let rects: Vec<(usize, usize, usize, usize)> = ps
            .iter()
            .zip(&atlas.placements)
            .map(|(p, pl)| (pl.x, pl.y, p.cols + 4, p.rows + 4))
            .collect();
        for (a, ra) in rects.iter().enumerate() {
            assert!(ra.0 + ra.2 <= side && ra.1 + ra.3 <= side);
            for rb in rects.iter().skip(a + 1) {
                let apart = ra.0 + ra.2 <= rb.0 || rb.0 + rb.2 <= ra.0 || ra.1 + ra.3 <= rb.1 || rb.1 + rb.3 <= ra.1;
                assert!(apart, "{ra:?} overlaps {rb:?}");
            }
        }
        for (k, p) in ps.iter().enumerate() {
            for (i, j) in [(0, 0), (p.cols - 1, p.rows - 1), (p.cols / 2, 1)] {
                let uv = atlas.uv(p, k, &p.texel_centre(i, j));
                let x = uv[0] * side as f64;
                let y = (1.0 - uv[1]) * side as f64;
                // The texel centre sits at a pixel centre: the lookup is exact.
                assert!((x.fract() - 0.5).abs() < 1e-9 && (y.fract() - 0.5).abs() < 1e-9);
                let got = atlas.lookup(0, x, y);
                assert_eq!(got, [k as f64, i as f64, j as f64], "patch {k} texel ({i}, {j})");
            }
        }
        // A patch larger than the page is refused by name.
        let small = AtlasSettings {
            gutter: 2,
            max_page: 32,
        };
        let err = pack(&scene, &ps, &textures, &small).unwrap_err().to_string();
        assert!(err.contains("\"a\"") && err.contains("texel"), "{err}");
    }
}
