//! Inverse global illumination indoors (thesis ch. 4, App. A): Ward BRDFs
//! and albedo maps recovered despite mutual illumination.
