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
    /// A PNG map (false colour, or radiance tone-mapped) with a colour bar
    /// under it that says what its colours mean.
    Map {
        /// The encoded image.
        bytes: Vec<u8>,
        /// Caption.
        caption: String,
        /// What the colours stand for.
        scale: ColourScale,
    },
    /// Figures side by side in one row that never wraps, sharing the
    /// page's width equally (a photograph, its re-render and the error
    /// map, for instance).
    Row(Vec<Figure>),
}

/// The meaning of a map's colours, drawn as a bar with its values.
#[derive(Debug, Clone, PartialEq)]
pub enum ColourScale {
    /// [`super::false_colour_png`]'s blue–white–red scale from `low` to
    /// `high` (white at the middle).
    Diverging {
        /// The value drawn blue (and below).
        low: f64,
        /// The value drawn red (and above).
        high: f64,
        /// Unit or meaning of the values, e.g. "relative error".
        unit: String,
    },
    /// [`super::tonemapped_png`]'s black to white (sRGB), white at `white`.
    Radiance {
        /// The value drawn white (and above).
        white: f64,
        /// Unit, e.g. "W·m⁻²·sr⁻¹".
        unit: String,
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

/// One line of the summary at the top of the page: a product, its
/// verdict, its headline figure beside its goal, and the section with its
/// detail.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SummaryRow {
    /// What was made, e.g. "Pseudo-albedos".
    pub product: String,
    /// Its quality verdict (`None`: not gated, e.g. a timing).
    pub verdict: Option<Verdict>,
    /// The headline figure, with its unit.
    pub figure: String,
    /// The goal or bound it is held to ("" when none).
    pub goal: String,
    /// The title of the section that has the detail ("" when none).
    pub section: String,
}

impl SummaryRow {
    /// A row for the products of `quality` whose names start with
    /// `prefix` (e.g. "sun " for every sun): the worst verdict among them,
    /// and as the figure either how many there are, all within their
    /// gates, or the worst one's figures against the bounds they passed.
    /// `None` when no product matches.
    pub fn from_quality(quality: &QualityReport, prefix: &str, product: &str, section: &str) -> Option<SummaryRow> {
        let matching: Vec<&ProductQuality> = quality
            .products
            .iter()
            .filter(|p| p.product.starts_with(prefix))
            .collect();
        // The first of the worst, in the products' order.
        let worst = matching.iter().rev().max_by_key(|p| p.verdict)?;
        let figure = match worst.verdict {
            Verdict::Ok => match matching.len() {
                1 => "within its gates".to_string(),
                n => format!("{n} products, all within their gates"),
            },
            v => {
                let count = matching.iter().filter(|p| p.verdict == v).count();
                let more = if count > 1 {
                    format!(" (and {} more {v})", count - 1)
                } else {
                    String::new()
                };
                format!("{}: {}{more}", worst.product, worst.reasons())
            }
        };
        Some(SummaryRow {
            product: product.to_string(),
            verdict: Some(worst.verdict),
            figure,
            goal: "the gates in quality.json".to_string(),
            section: section.to_string(),
        })
    }
}

/// The whole report.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Report {
    /// Page title.
    pub title: String,
    /// Lines under the title.
    pub intro: Vec<String>,
    /// The summary table at the top: one row per product.
    pub summary: Vec<SummaryRow>,
    /// The products' quality verdicts: a banner at the top names every
    /// `poor` or `failed` product with its figures.
    pub quality: Option<QualityReport>,
    /// Sections, in order.
    pub sections: Vec<Section>,
}

/// The mark a table cell starts with when its number is out of tolerance.
const FLAG: &str = "⚠ ";

/// A table cell whose number is out of its tolerance: drawn highlighted,
/// with a warning sign (so it survives copying the text).
pub fn flagged(text: impl std::fmt::Display) -> String {
    format!("{FLAG}{text}")
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

const STYLE: &str = "body{font-family:sans-serif;font-size:16px;max-width:1360px;margin:2em auto;padding:0 1em;color:#222}\
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}\
table{border-collapse:collapse;margin:1em 0;font-size:.9em;max-width:100%}td,th{border:1px solid #bbb;padding:.25em .6em;text-align:right}td{overflow-wrap:anywhere}\
th{background:#eee}td:first-child,th:first-child{text-align:left}caption{text-align:left;font-weight:bold;padding:.3em 0}\
td.flag{background:#fdd;color:#900;font-weight:bold}\
p,li,figcaption,caption{overflow-wrap:anywhere}\
.figs{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start}figure{margin:0;max-width:100%}\
figure img{max-width:100%;border:1px solid #ddd;image-rendering:pixelated}.figs figure img{min-width:360px}\
.row{display:flex;flex-wrap:nowrap;gap:.8em;width:100%;margin:.6em 0}.row figure{flex:1 1 0;min-width:0}.row figure svg.bar{max-width:100%}.row figure img{width:100%}\
figcaption{font-size:.85em;color:#444;max-width:640px}.row figcaption{max-width:none}\
svg.bar{display:block;margin-top:2px}nav{display:flex;flex-wrap:wrap;gap:.3em 1.2em;line-height:1.6}nav a{white-space:nowrap}\
.quality{border:2px solid;padding:.5em 1em;margin:1em 0}.quality ul{margin:.3em 0}\
.quality.ok{border-color:#2a7;background:#eefaf3}.quality.poor{border-color:#d90;background:#fff8e6}\
.quality.failed{border-color:#c22;background:#fdeeee}\
#summary{font-size:1em}#summary td{text-align:left}#summary th{white-space:nowrap;text-align:left}#summary td.ok{background:#dff3e6}#summary td.poor{background:#ffefc2}#summary td.failed{background:#f8d0d0;font-weight:bold}";

/// Run once the page has loaded: writes on `<body>` what a headless
/// browser's DOM dump can check: images decoded (`data-images-loaded`,
/// "N/M"), summary rows (`data-summary`), elements whose text overflows
/// their box or a page wider than the window (`data-overflow`, the first
/// in `data-overflow-first`), and the smallest font size of any text
/// (`data-min-font`, px).
const CHECK: &str = "window.addEventListener('load',function(){var b=document.body,i=document.images,n=0;\
for(var k=0;k<i.length;k++){if(i[k].complete&&i[k].naturalWidth>0)n++;}\
b.setAttribute('data-images-loaded',n+'/'+i.length);\
b.setAttribute('data-summary',document.querySelectorAll('#summary tr.product').length);\
var over=0,first='',min=1e9,e=document.querySelectorAll('h1,h2,p,li,td,th,caption,figcaption,nav a,svg.bar text');\
for(var k=0;k<e.length;k++){var x=e[k];var f=parseFloat(getComputedStyle(x).fontSize);\
if(x.textContent.trim()&&f<min)min=f;\
if(x.tagName!=='text'&&x.scrollWidth>x.clientWidth+1&&getComputedStyle(x).display!=='inline'){over++;if(!first)first=x.tagName+': '+x.textContent.slice(0,60);}}\
if(document.documentElement.scrollWidth>window.innerWidth+1){over++;if(!first)first='page wider than the window: '+document.documentElement.scrollWidth+' px';}\
b.setAttribute('data-overflow',over);b.setAttribute('data-overflow-first',first);b.setAttribute('data-min-font',Math.round(min*10)/10);});";

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

/// A number for a colour bar's label: short, in the figure's own terms.
fn tick(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e4 || v.abs() < 1e-3 {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// The colour bar under a map: the scale's gradient with its values
/// (inline SVG, 12 px text, not an image to decode).
fn colour_bar(scale: &ColourScale) -> String {
    let (stops, ticks, unit) = match scale {
        ColourScale::Diverging { low, high, unit } => (
            "<stop offset=\"0\" stop-color=\"#00f\"/><stop offset=\".5\" stop-color=\"#fff\"/><stop offset=\"1\" stop-color=\"#f00\"/>",
            [tick(*low), tick(0.5 * (low + high)), tick(*high)],
            unit,
        ),
        ColourScale::Radiance { white, unit } => (
            "<stop offset=\"0\" stop-color=\"#000\"/><stop offset=\"1\" stop-color=\"#fff\"/>",
            [tick(0.0), tick(0.5 * white), format!("≥ {}", tick(*white))],
            unit,
        ),
    };
    // An id per scale, so that the page's gradients do not collide.
    let id = {
        use std::hash::{DefaultHasher, Hash, Hasher};
        let mut h = DefaultHasher::new();
        format!("{scale:?}").hash(&mut h);
        format!("g{:x}", h.finish())
    };
    format!(
        "<svg class=\"bar\" width=\"320\" height=\"46\" viewBox=\"0 0 320 46\" role=\"img\" aria-label=\"colour scale\">\
<defs><linearGradient id=\"{id}\">{stops}</linearGradient></defs>\
<rect x=\"10\" y=\"2\" width=\"300\" height=\"12\" fill=\"url(#{id})\" stroke=\"#888\"/>\
<text x=\"10\" y=\"29\" font-size=\"12\" text-anchor=\"start\">{}</text>\
<text x=\"160\" y=\"29\" font-size=\"12\" text-anchor=\"middle\">{}</text>\
<text x=\"310\" y=\"29\" font-size=\"12\" text-anchor=\"end\">{}</text>\
<text x=\"160\" y=\"42\" font-size=\"11\" text-anchor=\"middle\" fill=\"#444\">{}</text></svg>",
        escape(&ticks[0]),
        escape(&ticks[1]),
        escape(&ticks[2]),
        escape(unit)
    )
}

fn png_uri(bytes: &[u8]) -> String {
    format!("data:image/png;base64,{}", STANDARD.encode(bytes))
}

/// One figure's HTML.
fn figure_html(f: &Figure) -> String {
    let img = |src: String, caption: &str, extra: String| {
        format!(
            "<figure><img src=\"{src}\" alt=\"{}\">{extra}<figcaption>{}</figcaption></figure>\n",
            escape(caption),
            escape(caption)
        )
    };
    match f {
        Figure::Png { bytes, caption } => img(png_uri(bytes), caption, String::new()),
        Figure::Svg { svg, caption } => img(
            format!("data:image/svg+xml;base64,{}", STANDARD.encode(svg.as_bytes())),
            caption,
            String::new(),
        ),
        Figure::Map { bytes, caption, scale } => img(png_uri(bytes), caption, colour_bar(scale)),
        Figure::Row(figures) => {
            // Maps that share one scale get one colour bar, under the row.
            let scales: Vec<&ColourScale> = figures
                .iter()
                .filter_map(|f| match f {
                    Figure::Map { scale, .. } => Some(scale),
                    _ => None,
                })
                .collect();
            let shared = (scales.len() == figures.len() && scales.len() > 1 && scales.windows(2).all(|w| w[0] == w[1]))
                .then(|| scales[0]);
            let mut h = String::from("<div class=\"row\">\n");
            for f in figures {
                match (f, shared) {
                    (Figure::Map { bytes, caption, .. }, Some(_)) => {
                        h.push_str(&img(png_uri(bytes), caption, String::new()));
                    }
                    _ => h.push_str(&figure_html(f)),
                }
            }
            h.push_str("</div>\n");
            if let Some(scale) = shared {
                h.push_str(&colour_bar(scale));
            }
            h
        }
    }
}

/// The summary at the top: per product its verdict, headline figure,
/// goal and a link to its section.
fn summary(rows: &[SummaryRow], sections: &[Section]) -> String {
    let mut h = String::from(
        "<table id=\"summary\"><caption>Summary</caption><tr><th>Product</th><th>Verdict</th><th>Figure</th><th>Goal</th><th>Detail</th></tr>\n",
    );
    for r in rows {
        let (class, verdict) = match r.verdict {
            Some(v) => (v.to_string(), v.to_string()),
            None => (String::new(), "—".to_string()),
        };
        let link = sections
            .iter()
            .position(|s| !r.section.is_empty() && s.title == r.section)
            .map_or_else(String::new, |i| format!("<a href=\"#s{i}\">{}</a>", escape(&r.section)));
        h.push_str(&format!(
            "<tr class=\"product\"><td>{}</td><td class=\"{class}\">{verdict}</td>{}<td>{}</td><td>{link}</td></tr>\n",
            escape(&r.product),
            cell(&r.figure),
            escape(&r.goal)
        ));
    }
    h.push_str("</table>\n");
    h
}

fn cell(c: &str) -> String {
    if c.starts_with(FLAG) {
        format!("<td class=\"flag\">{}</td>", escape(c))
    } else {
        format!("<td>{}</td>", escape(c))
    }
}

impl Report {
    /// The page, self-contained.
    pub fn to_html(&self) -> String {
        let mut h = String::new();
        h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
        h.push_str("<meta name=\"viewport\" content=\"width=device-width\">");
        h.push_str(&format!("<title>{}</title><style>{STYLE}</style>", escape(&self.title)));
        h.push_str(&format!("<script>{CHECK}</script></head>\n<body>\n"));
        h.push_str(&format!("<h1>{}</h1>\n", escape(&self.title)));
        if !self.summary.is_empty() {
            h.push_str(&summary(&self.summary, &self.sections));
        }
        if let Some(q) = &self.quality {
            h.push_str(&banner(q));
        }
        for line in &self.intro {
            h.push_str(&format!("<p>{}</p>\n", escape(line)));
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
                        h.push_str(&cell(c));
                    }
                    h.push_str("</tr>\n");
                }
                h.push_str("</table>\n");
            }
            // In order: rows as they come, the figures between them
            // together in one block that wraps.
            let mut loose = String::new();
            for f in &s.figures {
                if matches!(f, Figure::Row(_)) {
                    if !loose.is_empty() {
                        h.push_str(&format!("<div class=\"figs\">\n{loose}</div>\n"));
                        loose.clear();
                    }
                    h.push_str(&figure_html(f));
                } else {
                    loose.push_str(&figure_html(f));
                }
            }
            if !loose.is_empty() {
                h.push_str(&format!("<div class=\"figs\">\n{loose}</div>\n"));
            }
            h.push_str("</section>\n");
        }
        h.push_str("</body></html>\n");
        h
    }

    /// Number of images (a row counts its figures).
    pub fn figure_count(&self) -> usize {
        fn count(f: &Figure) -> usize {
            match f {
                Figure::Row(fs) => fs.iter().map(count).sum(),
                _ => 1,
            }
        }
        self.sections.iter().flat_map(|s| &s.figures).map(count).sum()
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
            summary: vec![],
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
    fn summary_rows_take_the_worst_verdict_and_link_their_section() {
        use crate::quality::{Better, Check, Gate, ProductQuality, Quality, QualityReport};
        let sun = |name: &str, spread: f64| {
            ProductQuality::new(
                format!("sun {name}"),
                vec![Check::new(
                    "triplet spread",
                    spread,
                    Gate::new(0.03, 0.15),
                    Better::Lower,
                )],
            )
        };
        let q = QualityReport::new(
            vec![
                sun("a", 0.01),
                sun("b", 0.05),
                sun("c", 0.04),
                ProductQuality::new("sky a", vec![]),
            ],
            &Quality::default(),
        );
        let row = SummaryRow::from_quality(&q, "sun ", "Sun", "Sun and extinction").unwrap();
        assert_eq!(row.verdict, Some(Verdict::Poor));
        assert_eq!(row.figure, "sun b: triplet spread 0.05 > 0.03 (and 1 more poor)");
        let sky = SummaryRow::from_quality(&q, "sky ", "Sky", "Sky").unwrap();
        assert_eq!(
            (sky.verdict, sky.figure.as_str()),
            (Some(Verdict::Ok), "within its gates")
        );
        assert!(SummaryRow::from_quality(&q, "room: ", "Room", "").is_none());
        let r = Report {
            title: "t".into(),
            summary: vec![row, sky],
            sections: vec![Section {
                title: "Sky".into(),
                ..Section::default()
            }],
            ..Report::default()
        };
        let html = r.to_html();
        assert!(html.contains("<td class=\"poor\">poor</td>"), "{html}");
        assert!(
            html.contains("<a href=\"#s0\">Sky</a></td>"),
            "the row links its section"
        );
        assert_eq!(html.matches("<tr class=\"product\">").count(), 2);
        assert!(html.find("id=\"summary\"").unwrap() < html.find("<nav>").unwrap());
    }

    #[test]
    fn flagged_cells_and_maps_are_drawn_with_their_marks() {
        let r = Report {
            title: "t".into(),
            sections: vec![Section {
                title: "s".into(),
                tables: vec![Table {
                    caption: "c".into(),
                    header: vec!["a".into(), "b".into()],
                    rows: vec![vec!["x".into(), flagged("1500 %")]],
                }],
                figures: vec![Figure::Row(vec![
                    Figure::Png {
                        bytes: vec![1],
                        caption: "photo".into(),
                    },
                    Figure::Map {
                        bytes: vec![2],
                        caption: "error".into(),
                        scale: ColourScale::Diverging {
                            low: -0.1,
                            high: 0.1,
                            unit: "relative error".into(),
                        },
                    },
                ])],
                ..Section::default()
            }],
            ..Report::default()
        };
        let html = r.to_html();
        assert!(html.contains("<td class=\"flag\">⚠ 1500 %</td>"), "{html}");
        assert!(html.contains("<div class=\"row\">"));
        assert!(html.contains("<svg class=\"bar\""));
        for label in [">-0.1<", ">0<", ">0.1<", ">relative error<"] {
            assert!(html.contains(label), "{label} on the colour bar");
        }
        assert_eq!(r.figure_count(), 2);
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
