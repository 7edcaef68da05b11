//! INDI's wire form: a stream of top-level XML elements, read one whole
//! element at a time, and the elements the client sends.

use std::io;

use quick_xml::escape::escape;
use quick_xml::events::Event;
use quick_xml::reader::Reader;
use tokio::io::{AsyncBufRead, BufReader};

/// One XML element with its attributes, children and text.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Element {
    /// The tag, e.g. `setNumberVector`.
    pub name: String,
    /// Attributes in order, unescaped.
    pub attrs: Vec<(String, String)>,
    /// Child elements in order.
    pub children: Vec<Element>,
    /// The text directly inside, unescaped.
    pub text: String,
}

impl Element {
    /// The value of attribute `name`.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    /// The number attribute `name` holds.
    pub fn number_attr(&self, name: &str) -> Option<f64> {
        self.attr(name).and_then(|v| v.trim().parse().ok())
    }
}

/// Reads whole top-level elements from an INDI stream.
pub struct ElementReader<R> {
    reader: Reader<R>,
    buf: Vec<u8>,
}

fn invalid(e: impl std::fmt::Display) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, format!("INDI stream: {e}"))
}

impl<R: tokio::io::AsyncRead + Unpin> ElementReader<BufReader<R>> {
    /// A reader over `stream`.
    pub fn new(stream: R) -> Self {
        let mut reader = Reader::from_reader(BufReader::with_capacity(1 << 16, stream));
        reader.config_mut().trim_text(false);
        ElementReader {
            reader,
            buf: Vec::new(),
        }
    }
}

impl<R: AsyncBufRead + Unpin> ElementReader<R> {
    /// The next whole top-level element; `None` at the end of the stream.
    pub async fn next(&mut self) -> io::Result<Option<Element>> {
        let mut stack: Vec<Element> = Vec::new();
        loop {
            self.buf.clear();
            let event = self
                .reader
                .read_event_into_async(&mut self.buf)
                .await
                .map_err(invalid)?;
            match event {
                Event::Start(e) => stack.push(start(&e)?),
                Event::Empty(e) => {
                    let el = start(&e)?;
                    match stack.last_mut() {
                        Some(parent) => parent.children.push(el),
                        None => return Ok(Some(el)),
                    }
                }
                Event::End(_) => {
                    let Some(el) = stack.pop() else {
                        return Err(invalid("a closing tag with no element open"));
                    };
                    match stack.last_mut() {
                        Some(parent) => parent.children.push(el),
                        None => return Ok(Some(el)),
                    }
                }
                Event::Text(t) => {
                    if let Some(el) = stack.last_mut() {
                        el.text += &t.decode().map_err(invalid)?;
                    }
                }
                Event::CData(t) => {
                    if let Some(el) = stack.last_mut() {
                        el.text += &t.decode().map_err(invalid)?;
                    }
                }
                Event::GeneralRef(r) => {
                    if let Some(el) = stack.last_mut() {
                        let name = r.decode().map_err(invalid)?;
                        let c = match r.resolve_char_ref().map_err(invalid)? {
                            Some(c) => c,
                            None => match name.as_ref() {
                                "lt" => '<',
                                "gt" => '>',
                                "amp" => '&',
                                "apos" => '\'',
                                "quot" => '"',
                                other => return Err(invalid(format!("unknown entity &{other};"))),
                            },
                        };
                        el.text.push(c);
                    }
                }
                Event::Eof => {
                    return if stack.is_empty() {
                        Ok(None)
                    } else {
                        Err(io::Error::new(
                            io::ErrorKind::UnexpectedEof,
                            format!("INDI stream ended inside <{}>", stack[0].name),
                        ))
                    };
                }
                Event::Decl(_) | Event::Comment(_) | Event::PI(_) | Event::DocType(_) => {}
            }
        }
    }
}

fn start(e: &quick_xml::events::BytesStart<'_>) -> io::Result<Element> {
    let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
    let mut attrs = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(invalid)?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value = a.unescape_value().map_err(invalid)?.into_owned();
        attrs.push((key, value));
    }
    Ok(Element {
        name,
        attrs,
        ..Element::default()
    })
}

/// `<getProperties version="1.7"/>`, for one device or all.
pub fn get_properties(device: Option<&str>) -> String {
    match device {
        Some(d) => format!("<getProperties version=\"1.7\" device=\"{}\"/>\n", escape(d)),
        None => "<getProperties version=\"1.7\"/>\n".to_owned(),
    }
}

/// `<enableBLOB device="…">Also</enableBLOB>`: BLOBs along with the rest.
pub fn enable_blob(device: &str) -> String {
    format!("<enableBLOB device=\"{}\">Also</enableBLOB>\n", escape(device))
}

/// A `new{Number,Switch,Text}Vector` asking `device`'s property `name` for
/// the element values `items` (`kind` is `Number`, `Switch` or `Text`).
pub fn new_vector(kind: &str, device: &str, name: &str, items: &[(&str, String)]) -> String {
    let mut s = format!(
        "<new{kind}Vector device=\"{}\" name=\"{}\">\n",
        escape(device),
        escape(name)
    );
    for (element, value) in items {
        s += &format!(
            "  <one{kind} name=\"{}\">{}</one{kind}>\n",
            escape(*element),
            escape(value.as_str())
        );
    }
    s += &format!("</new{kind}Vector>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn elements_are_read_whole_in_order_with_entities() {
        let wire = br#"<defNumberVector device="CCD &amp; Co" name="CCD_EXPOSURE" state="Idle" perm="rw">
<defNumber name="CCD_EXPOSURE_VALUE" format="%5.2f" min="0.001" max="3600" step="1">
1
</defNumber>
</defNumberVector>
<message device="CCD &amp; Co" message="a &lt;b&gt;"/>
<setBLOBVector device="X" name="CCD1" state="Ok"><oneBLOB name="CCD1" size="3" format=".fits" len="4">QUJD
</oneBLOB></setBLOBVector>"#;
        let mut r = ElementReader::new(&wire[..]);
        let def = r.next().await.unwrap().unwrap();
        assert_eq!(def.name, "defNumberVector");
        assert_eq!(def.attr("device"), Some("CCD & Co"));
        assert_eq!(def.children[0].number_attr("max"), Some(3600.0));
        assert_eq!(def.children[0].text.trim(), "1");
        let msg = r.next().await.unwrap().unwrap();
        assert_eq!(msg.attr("message"), Some("a <b>"));
        let blob = r.next().await.unwrap().unwrap();
        assert_eq!(blob.children[0].text.trim(), "QUJD");
        assert!(r.next().await.unwrap().is_none());
    }

    #[tokio::test]
    async fn a_stream_cut_inside_an_element_is_an_error() {
        let mut r = ElementReader::new(&b"<setNumberVector device=\"X\"><oneNumber"[..]);
        assert!(r.next().await.is_err());
    }

    #[test]
    fn requests_are_escaped() {
        let s = new_vector("Number", "A&B", "CCD_EXPOSURE", &[("CCD_EXPOSURE_VALUE", "0.5".into())]);
        assert!(
            s.starts_with("<newNumberVector device=\"A&amp;B\" name=\"CCD_EXPOSURE\">"),
            "{s}"
        );
        assert!(
            s.contains("<oneNumber name=\"CCD_EXPOSURE_VALUE\">0.5</oneNumber>"),
            "{s}"
        );
    }
}
