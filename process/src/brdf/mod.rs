//! Reflectance models (thesis appendix A): Lambertian and Ward, each naming its normalization variant.
