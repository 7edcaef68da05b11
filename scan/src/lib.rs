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
//!
//! The crate is separate from `campanile-process` because nothing in the
//! reflectance and light solvers needs it and it needs none of them: it is
//! pure, synchronous and deterministic like `process`, and depends on no other
//! crate of ours.
//!
//! Conventions: the scene frame is right-handed, z up, x east, y north, in
//! metres (`DESIGN.md`, "World frame").

pub mod cloud;
pub mod read;
pub mod segmentation;
pub mod write;
