//! Range scans to a scene's geometry: thesis chapter 2.
//!
//! A terrestrial laser scanner, a phone or a photogrammetry package gives
//! points; the reflectance chapters need surfaces with names. This crate goes
//! from one to the other:
//!
//! - [`cloud`]: the scan as data, one scanner's points in the scene frame,
//!   with their normals, intensity and colour when the file has them, and the
//!   scanner's rows and columns when the scan is organised (a range image).
//! - [`segmentation`]: every point's surface group (the segmenter's answer,
//!   or the simulator's truth).
//! - [`read`]: scans from PLY, E57 and LAS/LAZ files, and several registered
//!   scans streamed one at a time ([`read::stream`]).
//! - [`write`](mod@write): scans to PLY and E57 files (the simulator's, the tests').
//! - [`mesh`]: a mesh per surface group (§2.4): planar polygons, scan-order
//!   triangles, height fields and ball pivoting; quadric-error
//!   simplification; the Hausdorff distance to the true geometry.
//! - [`obj_file`]: meshes as an OBJ with one group each, and back.
//! - [`skeleton`]: the scene-file skeleton (`surfaces`, `groups`) that
//!   `campanile igi`, `process` and `render` take.
//! - [`segmentation_ply`]: the points coloured by group; [`group_view`]: a
//!   picture of them for the report page.
//! - [`reconstruction`]: scans and segmentation to a scene directory (OBJ,
//!   skeleton, PLY, report with a verdict): the one call behind
//!   `campanile segment`.
//! - [`scene_from_scans`]: the whole of `campanile segment`: read, segment,
//!   mesh, write the scene directory and its report page.
//! - [`synthetic_scan`]: an ideal organised scanner over axis-aligned
//!   rectangles (a box room, a cabinet), with the true segmentation and
//!   geometry, for tests and benchmarks.
//! - [`edit`]: scene editing (§2.5.2): groups merged into objects, objects
//!   moved, copied and deleted.
//! - [`segment`]: normalized-cut segmentation (§2.3): normals, the cluster
//!   graph, recursive cuts, boundary voting, fine segmentation, targets,
//!   and metrics against the truth.
//!
//! The crate is separate from `campanile-process` because nothing in the
//! reflectance and light solvers needs it and it needs none of them: it is
//! pure, synchronous and deterministic like `process`, and depends on no other
//! crate of ours.
//!
//! Conventions: the scene frame is right-handed, z up, x east, y north, in
//! metres (`DESIGN.md`, "World frame").

pub mod cloud;
pub mod edit;
pub mod group_view;
pub mod mesh;
pub mod obj_file;
pub mod read;
pub mod reconstruction;
pub mod scene_from_scans;
pub mod segment;
pub mod segmentation;
pub mod segmentation_ply;
pub mod skeleton;
pub mod synthetic_scan;
pub mod write;
