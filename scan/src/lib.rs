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
pub mod segment;
pub mod segmentation;
