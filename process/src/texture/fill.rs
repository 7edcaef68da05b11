//! Filling the texels no photograph gave a value (unseen texels on a face,
//! and the padding around a face's triangles) from their neighbours, in
//! rings: each pass gives every empty texel with at least one valued
//! 8-neighbour the mean of those neighbours, so values spread outward from
//! the seen texels, nearest first. The status of each texel (seen, filled,
//! padding) is kept, so the reader knows what was measured. A patch that no
//! photograph saw at all stays black (and its report says it was unseen).

use super::synthesis::{PatchTexture, TexelStatus};

/// Fills the texels of `tex` (a `cols × rows` patch) whose status is not [`TexelStatus::Seen`].
pub fn fill_patch(tex: &mut PatchTexture, cols: usize, rows: usize) {
    let mut known: Vec<bool> = tex.status.iter().map(|s| *s == TexelStatus::Seen).collect();
    if !known.iter().any(|&k| k) {
        tex.rgb.iter_mut().for_each(|c| *c = [0.0; 3]);
        return;
    }
    loop {
        let mut updates: Vec<(usize, [f32; 3])> = Vec::new();
        for j in 0..rows {
            for i in 0..cols {
                let idx = j * cols + i;
                if known[idx] {
                    continue;
                }
                let mut sum = [0f32; 3];
                let mut n = 0u32;
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (ii, jj) = (i as i64 + di, j as i64 + dj);
                        if (di, dj) == (0, 0) || ii < 0 || jj < 0 || ii >= cols as i64 || jj >= rows as i64 {
                            continue;
                        }
                        let k = jj as usize * cols + ii as usize;
                        if known[k] {
                            (0..3).for_each(|c| sum[c] += tex.rgb[k][c]);
                            n += 1;
                        }
                    }
                }
                if n > 0 {
                    updates.push((idx, sum.map(|x| x / n as f32)));
                }
            }
        }
        if updates.is_empty() {
            break;
        }
        for (idx, v) in updates {
            tex.rgb[idx] = v;
            known[idx] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 1 strip seen only at its ends (1 and 4): the middle texels take
    /// their nearer end's value in the first ring; statuses are kept.
    #[test]
    fn holes_fill_from_the_nearest_seen_texels() {
        let mut tex = PatchTexture {
            rgb: vec![[1.0; 3], [0.0; 3], [0.0; 3], [4.0; 3]],
            weight: vec![1.0, 0.0, 0.0, 1.0],
            status: vec![
                TexelStatus::Seen,
                TexelStatus::Filled,
                TexelStatus::Padding,
                TexelStatus::Seen,
            ],
            photos: vec![1, 0, 0, 1],
            spread: vec![0.0; 4],
        };
        fill_patch(&mut tex, 4, 1);
        assert_eq!(tex.rgb[1], [1.0; 3]);
        assert_eq!(tex.rgb[2], [4.0; 3]);
        assert_eq!(tex.status[1], TexelStatus::Filled);
        // Nothing seen: black.
        let mut none = PatchTexture {
            rgb: vec![[7.0; 3]; 2],
            weight: vec![0.0; 2],
            status: vec![TexelStatus::Filled; 2],
            photos: vec![0; 2],
            spread: vec![0.0; 2],
        };
        fill_patch(&mut none, 2, 1);
        assert_eq!(none.rgb, vec![[0.0; 3]; 2]);
    }
}
