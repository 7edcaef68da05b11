//! The page: sections of paragraphs, tables and figures, written as HTML.

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;

use crate::quality::{ProductQuality, QualityReport, Verdict};

/// A figure: an inline image with a caption.
#[derive(Debug, Clone, PartialEq)]
pub enum Figure {
    /// PNG bytes.
    Png {
        /// The encoded image.
        bytes: Vec<u8>,
        /// Caption.
        caption: String,
    },
    /// An SVG document.
    Svg {
        /// The document.
        svg: String,
        /// Caption.
        caption: String,
    },
}

/// A table with a header row.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Caption above it.
    pub caption: String,
    /// Column headings.
    pub header: Vec<String>,
    /// Rows of cells (text).
    pub rows: Vec<Vec<String>>,
}

/// A section of the report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Section {
    /// Heading.
    pub title: String,
    /// Paragraphs of plain text (escaped).
    pub paragraphs: Vec<String>,
    /// Tables, after the paragraphs.
    pub tables: Vec<Table>,
    /// Figures, after the tables, laid out in a row that wraps.
    pub figures: Vec<Figure>,
}

/// The whole report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Report {
    /// Page title.
    pub title: String,
    /// Lines under the title.
    pub intro: Vec<String>,
    /// The products' quality verdicts: a banner at the top names every
    /// `poor` or `failed` product with its figures.
    pub quality: Option<QualityReport>,
    /// Sections, in order.
    pub sections: Vec<Section>,
}

fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}\
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}\
table{border-collapse:collapse;margin:1em 0;font-size:.9em}td,th{border:1px solid #bbb;padding:.25em .6em;text-align:right}\
th{background:#eee}td:first-child,th:first-child{text-align:left}caption{text-align:left;font-weight:bold;padding:.3em 0}\
.figs{display:flex;flex-wrap:wrap;gap:1em}figure{margin:0}figure img{max-width:560px;border:1px solid #ddd;image-rendering:pixelated}\
figcaption{font-size:.85em;color:#555;max-width:560px}nav a{margin-right:1em}\
.quality{border:2px solid;padding:.5em 1em;margin:1em 0}.quality ul{margin:.3em 0}\
.quality.ok{border-color:#2a7;background:#eefaf3}.quality.poor{border-color:#d90;background:#fff8e6}\
.quality.failed{border-color:#c22;background:#fdeeee}";

const CHECK: &str = "window.addEventListener('load',function(){var i=document.images,n=0;\
for(var k=0;k<i.length;k++){if(i[k].complete&&i[k].naturalWidth>0)n++;}\
document.body.setAttribute('data-images-loaded',n+'/'+i.length);});";

/// The quality banner: the overall verdict, then every `failed` and
/// `poor` product with the figures that put it there.
fn banner(q: &QualityReport) -> String {
    let c = q.counts;
    let mut h = format!(
        "<div class=\"quality {}\" id=\"quality\"><strong>Quality: {}</strong> ({} ok, {} poor, {} failed; every figure and threshold in quality.json)",
        q.verdict, q.verdict, c.ok, c.poor, c.failed
    );
    let item = |verdict: Verdict, p: &ProductQuality| {
        format!(
            "<li><b>{verdict}</b> {}: {}</li>",
            escape(&p.product),
            escape(&p.reasons())
        )
    };
    for verdict in [Verdict::Failed, Verdict::Poor] {
        // Those that are so by their own figures, then one line for those
        // that only inherited it (they can be many: every map of a curve).
        let (own, inherited): (Vec<&ProductQuality>, Vec<&ProductQuality>) =
            q.with(verdict).partition(|p| p.own_verdict == verdict);
        let mut items: Vec<String> = own.iter().map(|p| item(verdict, p)).collect();
        match inherited.as_slice() {
            [] => {}
            [p] => items.push(item(verdict, p)),
            many => {
                let mut from: Vec<&str> = many
                    .iter()
                    .flat_map(|p| p.inherited.iter().map(String::as_str))
                    .collect();
                from.sort_unstable();
                from.dedup();
                items.push(format!(
                    "<li><b>{verdict}</b> {} more products, through what they inherited from {}</li>",
                    many.len(),
                    escape(&from.join(", "))
                ));
            }
        }
        if !items.is_empty() {
            h.push_str(&format!("<ul>{}</ul>", items.join("")));
        }
    }
    h.push_str("</div>\n");
    h
}

impl Report {
    /// The page, self-contained.
    pub fn to_html(&self) -> String {
        let mut h = String::new();
        h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
        h.push_str(&format!("<title>{}</title><style>{STYLE}</style>", escape(&self.title)));
        h.push_str(&format!("<script>{CHECK}</script></head>\n<body>\n"));
        h.push_str(&format!("<h1>{}</h1>\n", escape(&self.title)));
        for line in &self.intro {
            h.push_str(&format!("<p>{}</p>\n", escape(line)));
        }
        if let Some(q) = &self.quality {
            h.push_str(&banner(q));
        }
        h.push_str("<nav>");
        for (i, s) in self.sections.iter().enumerate() {
            h.push_str(&format!("<a href=\"#s{i}\">{}</a>", escape(&s.title)));
        }
        h.push_str("</nav>\n");
        for (i, s) in self.sections.iter().enumerate() {
            h.push_str(&format!("<section id=\"s{i}\"><h2>{}</h2>\n", escape(&s.title)));
            for p in &s.paragraphs {
                h.push_str(&format!("<p>{}</p>\n", escape(p)));
            }
            for t in &s.tables {
                h.push_str(&format!("<table><caption>{}</caption><tr>", escape(&t.caption)));
                for c in &t.header {
                    h.push_str(&format!("<th>{}</th>", escape(c)));
                }
                h.push_str("</tr>\n");
                for row in &t.rows {
                    h.push_str("<tr>");
                    for c in row {
                        h.push_str(&format!("<td>{}</td>", escape(c)));
                    }
                    h.push_str("</tr>\n");
                }
                h.push_str("</table>\n");
            }
            if !s.figures.is_empty() {
                h.push_str("<div class=\"figs\">\n");
                for f in &s.figures {
                    let (src, caption) = match f {
                        Figure::Png { bytes, caption } => {
                            (format!("data:image/png;base64,{}", STANDARD.encode(bytes)), caption)
                        }
                        Figure::Svg { svg, caption } => (
                            format!("data:image/svg+xml;base64,{}", STANDARD.encode(svg.as_bytes())),
                            caption,
                        ),
                    };
                    h.push_str(&format!(
                        "<figure><img src=\"{src}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
                        escape(caption),
                        escape(caption)
                    ));
                }
                h.push_str("</div>\n");
            }
            h.push_str("</section>\n");
        }
        h.push_str("</body></html>\n");
        h
    }

    /// Number of figures.
    pub fn figure_count(&self) -> usize {
        self.sections.iter().map(|s| s.figures.len()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_and_images_inlined() {
        let r = Report {
            title: "a <b> & c".into(),
            intro: vec![],
            quality: None,
            sections: vec![Section {
                title: "s".into(),
                paragraphs: vec!["x < y".into()],
                tables: vec![Table {
                    caption: "t".into(),
                    header: vec!["h".into()],
                    rows: vec![vec!["\"q\"".into()]],
                }],
                figures: vec![Figure::Svg {
                    svg: "<svg xmlns='http://www.w3.org/2000/svg'/>".into(),
                    caption: "c".into(),
                }],
            }],
        };
        let html = r.to_html();
        assert!(html.contains("<h1>a &lt;b&gt; &amp; c</h1>"));
        assert!(html.contains("<p>x &lt; y</p>"));
        assert!(html.contains("<td>&quot;q&quot;</td>"));
        // "<svg xmlns='http://www.w3.org/2000/svg'/>" in base64.
        assert!(html.contains("data:image/svg+xml;base64,PHN2ZyB4bWxucz0naHR0cDovL3d3dy53My5vcmcvMjAwMC9zdmcnLz4="));
        assert_eq!(r.figure_count(), 1);
    }

    #[test]
    fn the_banner_names_every_failed_and_poor_product_with_its_figures() {
        use crate::quality::{Better, Check, Gate, ProductQuality, Quality, QualityReport};
        let failed = ProductQuality::new(
            "response",
            vec![Check::new(
                "condition estimate",
                1.2e9,
                Gate::new(1e6, 1e8),
                Better::Lower,
            )],
        );
        let poor = ProductQuality::new(
            "sun s@1",
            vec![Check::new("triplet spread", 0.05, Gate::new(0.03, 0.15), Better::Lower)],
        );
        let ok = ProductQuality::new("sky s@1", vec![]);
        let heirs: Vec<ProductQuality> = (0..2)
            .map(|k| {
                let mut p = ProductQuality::new(format!("radiance m{k}"), vec![]);
                p.inherit(&failed);
                p
            })
            .collect();
        let mut products = vec![failed, poor, ok];
        products.extend(heirs);
        let r = Report {
            title: "t".into(),
            quality: Some(QualityReport::new(products, &Quality::default())),
            ..Report::default()
        };
        let html = r.to_html();
        let banner = &html[html.find("<div class=\"quality failed\"").expect("a failed banner")..];
        let banner = &banner[..banner.find("</div>").unwrap()];
        assert!(banner.contains("1 ok, 1 poor, 3 failed"), "{banner}");
        assert!(
            banner
                .contains("<li><b>failed</b> 2 more products, through what they inherited from response: failed</li>"),
            "{banner}"
        );
        assert!(
            banner.contains("<li><b>failed</b> response: condition estimate 1.2e9 &gt; 1e8</li>"),
            "{banner}"
        );
        assert!(
            banner.contains("<li><b>poor</b> sun s@1: triplet spread 0.05 &gt; 0.03</li>"),
            "{banner}"
        );
        assert!(!banner.contains("sky s@1"), "ok products are only counted: {banner}");
        // It comes before the first section.
        assert!(html.find("id=\"quality\"").unwrap() < html.find("<nav>").unwrap());
    }
}
