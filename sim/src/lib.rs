//! The simulated station. See the README table for what exists.
