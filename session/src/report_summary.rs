//! The summary at the top of every report page: per product, its verdict,
//! its headline figure beside its goal, and the section with the detail.

use campanile_process::quality::QualityReport;
use campanile_process::report::SummaryRow;

/// The product groups a session's quality report can hold, as (product
/// name prefix, what the reader is told, the section with the detail).
const GROUPS: &[(&str, &str, &str)] = &[
    ("response", "Camera response", "Camera response"),
    ("radiance ", "HDR radiance maps", "Camera response"),
    ("sun ", "Sun irradiance", "Sun and extinction"),
    ("sky ", "Sky models (eq. 5.9)", "Sky"),
    ("environment", "Environment", "Environment"),
    ("pseudo-albedos", "Pseudo-albedos (ch. 5)", "Pseudo-albedos"),
    ("outdoor", "Outdoor re-rendering", "Held-out time"),
    (
        "room: response",
        "Room: camera response",
        "Indoor: the room relit (inverse global illumination, §4.7.2)",
    ),
    (
        "room: radiance ",
        "Room: HDR views",
        "Indoor: the room relit (inverse global illumination, §4.7.2)",
    ),
    (
        "room: brdf ",
        "Room: BRDFs (ch. 4)",
        "Indoor: the room relit (inverse global illumination, §4.7.2)",
    ),
    (
        "brdf ",
        "BRDFs (ch. 4)",
        "Indoor: the room (inverse global illumination, §4.7.2)",
    ),
    (
        "lamp",
        "Lamps",
        "Indoor: the room (inverse global illumination, §4.7.2)",
    ),
];

/// One row per product group present in `quality`, in [`GROUPS`]'s order,
/// then one for any product no group takes.
pub fn from_quality(quality: &QualityReport) -> Vec<SummaryRow> {
    let mut rows: Vec<SummaryRow> = GROUPS
        .iter()
        .filter_map(|(prefix, product, section)| SummaryRow::from_quality(quality, prefix, product, section))
        .collect();
    // A product of a kind no group names gets a row of its own (its name
    // as the prefix, which also takes any product whose name extends it).
    let mut taken: Vec<&str> = GROUPS.iter().map(|(prefix, _, _)| *prefix).collect();
    for p in &quality.products {
        let name = p.product.as_str();
        if !taken.iter().any(|prefix| name.starts_with(prefix))
            && let Some(row) = SummaryRow::from_quality(quality, name, name, "")
        {
            rows.push(row);
            taken.push(name);
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_process::quality::{Better, Check, Gate, ProductQuality, Quality, Verdict};

    #[test]
    fn every_product_is_in_one_row() {
        let q = QualityReport::new(
            vec![
                ProductQuality::new("response", vec![]),
                ProductQuality::new("radiance a", vec![]),
                ProductQuality::new(
                    "sun a",
                    vec![Check::new("triplet spread", 0.2, Gate::new(0.03, 0.15), Better::Lower)],
                ),
                ProductQuality::new("igi interreflection", vec![]),
            ],
            &Quality::default(),
        );
        let rows = from_quality(&q);
        let names: Vec<&str> = rows.iter().map(|r| r.product.as_str()).collect();
        assert_eq!(
            names,
            [
                "Camera response",
                "HDR radiance maps",
                "Sun irradiance",
                "igi interreflection"
            ]
        );
        assert_eq!(rows[2].verdict, Some(Verdict::Failed));
        assert_eq!(rows[2].section, "Sun and extinction");
    }
}
