//! The science: pure, synchronous, deterministic solvers. See the README table for what exists.
