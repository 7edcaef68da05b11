//! The crash-safe session store (being written).
