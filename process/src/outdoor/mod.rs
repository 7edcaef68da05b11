//! Outdoor reflectance recovery and re-rendering at novel times (thesis ch. 5):
//! pseudo-albedos ρ_sun and ρ_se (eqs. 5.11–5.12) and radiance at any time.
