//! Inverse global illumination indoors (thesis ch. 4, App. A): each
//! surface's Ward BRDF recovered from radiance images despite mutual
//! illumination.
//!
//! Entry point: [`recover`]`(&IgiInput, &IgiOptions) -> Result<IgiResult, IgiError>`;
//! [`format_table`] prints the result in the layout of the thesis's Table 4.1.
//!
//! - [`camera`]: the views' pinhole cameras.
//! - [`input`]: geometry, lights, views, options.
//! - `geometry`: ray casting and the radiosity cells; `observation`: the
//!   samples; `radiosity`: inverse radiosity (§4.3) and gathering;
//!   `delta_s`: the indirect specular term (§4.5.1); `ward_fit`: golden
//!   section / downhill simplex + linear least squares (App. A);
//!   [`highlight`]: highlight detection (Fig. 4.4); `recover`: the ΔS loop
//!   and model choice; `stratified`: the strata of the Monte Carlo rays;
//!   [`lamp_paths`]: light paths under point lamps (relighting, albedo
//!   maps, the simulator's photographs); [`relight`]: the room under new
//!   lamps, and [`error_target`]: the same with paths drawn per block
//!   until an error target is met.
//!
//! Ward normalization: the solver fits the lobe in the variant
//! [`IgiOptions::variant`] names, by default
//! [`crate::brdf::WardVariant::Ward1992`], the thesis's eq. A.1/A.2.

// Colour channels are indexed 0..3 alike across several arrays at once.
#![allow(clippy::needless_range_loop)]

pub mod albedo_chart;
pub mod albedo_map;
pub mod camera;
mod delta_s;
mod error;
pub mod error_target;
mod geometry;
pub mod highlight;
pub mod input;
pub mod interreflection_check;
pub mod lamp_paths;
pub mod light_triangulation;
pub mod material_record;
mod observation;
pub mod radiance_view;
mod radiosity;
mod recover;
pub mod relight;
pub mod relit_scene;
pub mod scene_file;
mod specular_albedo;
mod stratified;
pub mod table;
pub mod texel_groups;
pub mod uncertainty;
pub mod variant_choice;
mod ward_fit;

pub use camera::ViewCamera;
pub use error::IgiError;
pub use input::{IgiInput, IgiLight, IgiOptions, View};
pub use observation::DroppedPixels;
pub use recover::{
    IgiProgress, IgiResult, IterationReport, PredictedSample, SpecularKind, SurfaceModel, SurfaceResult,
    canonical_lobe, gather_rays_per_cell, predict, recover, recover_with_progress, specular_kind,
};
pub use table::format_table;
