//! Texture maps from registered photographs, thesis §3.4 ("Texture Map
//! Synthesis and Compression").
//!
//! Each surface of the model gets one texture patch that is "an
//! appropriately weighted average of the projected areas of the triangle in
//! all photographs" (§3.4, Fig. 3.3). Here a patch covers a *face*: the
//! coplanar triangles of one named surface, on the face's planar texture
//! axes ([`crate::render::Triangle::texture_coordinates`]), at a chosen
//! texel size in metres. Then:
//!
//! - [`patch`]: the faces and their texel lattices (which texels lie on a
//!   triangle of the face).
//! - [`photo`]: a registered photograph: radiance image and camera.
//! - [`weight`]: each photograph's weight at a texel: smaller at grazing
//!   views and near the photograph's border (§3.4), and smaller where the
//!   texel covers less than a pixel (resolution).
//! - [`synthesis`]: the weighted average per texel over the photographs that
//!   see it (a ray from the camera meets nothing before the texel: the
//!   visibility of §3.5 tested per texel), then [`fill`]: texels no
//!   photograph sees are counted and filled from their neighbours, never
//!   invented silently.
//! - [`atlas`]: the patches packed into atlas pages (the `rectangle-pack`
//!   crate; the thesis's first-fit pairs of triangles are its own packer),
//!   with a gutter of copied texels so that filtering does not bleed, and
//!   each vertex's texture coordinates.
//! - [`export`]: OBJ + MTL + atlas images (OpenEXR radiance, PNG preview
//!   through a tone map).
//! - [`albedo`]: the same patches from the recovered pseudo-albedos
//!   (thesis ch. 5) instead of photographs: albedo textures.
//! - [`igi_albedo`]: the same patches from the diffuse albedo maps of
//!   inverse global illumination (thesis §4.6).
//! - [`seam`]: how visible the patch borders are (the difference across
//!   shared edges against the difference between neighbouring texels
//!   inside a patch), and the verdict.
//!
//! Not done: the thesis's texture-patch resizing by edge response and
//! patch clustering (its 4× compression scheme; compression here is left to
//! standard HDR image formats, BENCHMARKS.md "Texture maps"); triangles
//! that are not planar with their face's neighbours get a patch each.

pub mod albedo;
pub mod atlas;
pub mod export;
pub mod fill;
pub mod igi_albedo;
pub mod patch;
pub mod photo;
pub mod seam;
pub mod synthesis;
pub mod weight;

pub use albedo::{AlbedoSource, PseudoAlbedo, albedo_synthesis, judge_albedo, judge_albedo_from};
pub use atlas::{Atlas, AtlasSettings, pack};
pub use igi_albedo::{ChartData, igi_albedo_synthesis};
pub use patch::{Patch, patches, patches_on_lattice};
pub use photo::{TexturePhoto, pose_from_angles};
pub use seam::{Quality, QualityLimits, SeamFigures, judge, seam_figures};
pub use synthesis::{
    PatchTexture, Synthesis, SynthesisReport, SynthesisSettings, synthesize, synthesize_with_progress,
};

/// Why texture maps could not be made.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// A setting is out of range.
    #[error("texture settings: {field} = {value}, expected {expected}")]
    BadSetting {
        /// The field.
        field: &'static str,
        /// The value given.
        value: String,
        /// What it must be.
        expected: String,
    },
    /// A surface was asked for that the scene does not have.
    #[error("surface {name:?} is not in the scene (it has: {known})")]
    UnknownSurface {
        /// The name asked for.
        name: String,
        /// The scene's surfaces, comma-separated.
        known: String,
    },
    /// A surface was asked for that the albedo products do not cover.
    #[error("surface {name:?} has no recovered albedo (the albedo products cover: {covered})")]
    NotInProducts {
        /// The surface.
        name: String,
        /// The surfaces the products cover, comma-separated.
        covered: String,
    },
    /// A photograph's buffer does not match its size, or its size its camera's.
    #[error("photo {photo:?}: {what}")]
    BadPhoto {
        /// The photograph.
        photo: String,
        /// What is wrong and what was expected.
        what: String,
    },
    /// A patch is larger than an atlas page.
    #[error(
        "surface {surface:?}: its patch is {width} × {height} texels, larger than the {page} × {page} atlas page; \
         use a larger texel size"
    )]
    PatchTooLarge {
        /// The surface.
        surface: String,
        /// Patch width with its gutter, texels.
        width: usize,
        /// Patch height with its gutter, texels.
        height: usize,
        /// Page side, texels.
        page: usize,
    },
    /// The patches hold more texels than the limit.
    #[error("{texels} texels at {texel_m} m per texel exceed the limit of {limit}; use a larger texel size")]
    TooManyTexels {
        /// Texels needed.
        texels: usize,
        /// Texel size, metres.
        texel_m: f64,
        /// The limit.
        limit: usize,
    },
    /// An output file could not be written.
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong.
        message: String,
    },
}
