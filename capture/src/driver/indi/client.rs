//! An INDI client: one TCP connection to an `indiserver`, a task that
//! reads its elements into a mirror of every device's properties (and the
//! BLOBs that arrive), and requests written back.

use std::collections::{BTreeMap, VecDeque};
use std::io;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use base64::Engine;
use campanile_firmware_link::driver_error::DriverError;
use tokio::io::AsyncWriteExt;
use tokio::net::TcpStream;
use tokio::net::tcp::OwnedWriteHalf;
use tokio::sync::watch;
use tokio::task::JoinHandle;

use super::element::{self, Element, ElementReader};
use crate::device::DeviceError;

/// What a property vector holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PropertyKind {
    /// Numbers (`defNumberVector`).
    Number,
    /// Switches, On or Off (`defSwitchVector`).
    Switch,
    /// Text (`defTextVector`).
    Text,
    /// Status lights (`defLightVector`).
    Light,
    /// Binary large objects: images (`defBLOBVector`).
    Blob,
}

/// A property vector's state, as the device last reported it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PropertyState {
    /// Not active.
    Idle,
    /// Done, or as asked.
    Ok,
    /// Working on a request.
    Busy,
    /// Failed.
    Alert,
}

impl PropertyState {
    fn parse(text: Option<&str>) -> Option<Self> {
        match text? {
            "Idle" => Some(Self::Idle),
            "Ok" => Some(Self::Ok),
            "Busy" => Some(Self::Busy),
            "Alert" => Some(Self::Alert),
            _ => None,
        }
    }
}

/// One element of a property vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Item {
    /// Its name, e.g. `CCD_EXPOSURE_VALUE`.
    pub name: String,
    /// Its label for people.
    pub label: String,
    /// Its value as sent (a number, `On`/`Off`, text or a light's state).
    pub value: String,
    /// A number's least allowed value.
    pub min: Option<f64>,
    /// A number's largest allowed value.
    pub max: Option<f64>,
    /// A number's step (0: any value).
    pub step: Option<f64>,
}

/// A device's property vector, as last defined and set.
#[derive(Debug, Clone, PartialEq)]
pub struct Property {
    /// The device, e.g. `CCD Simulator`.
    pub device: String,
    /// The property, e.g. `CCD_EXPOSURE`.
    pub name: String,
    /// What it holds.
    pub kind: PropertyKind,
    /// Its state.
    pub state: PropertyState,
    /// Its permission (`ro`, `wo`, `rw`).
    pub perm: String,
    /// Its elements, in order.
    pub items: Vec<Item>,
    /// The mirror's count of elements read when this property was last
    /// defined or set (see [`Mirror::read`]).
    pub updated: u64,
}

impl Property {
    /// The element called `name`.
    pub fn item(&self, name: &str) -> Option<&Item> {
        self.items.iter().find(|i| i.name == name)
    }

    /// The number element `name` holds (plain or sexagesimal `d:m:s`).
    pub fn number(&self, name: &str) -> Option<f64> {
        self.item(name).and_then(|i| parse_number(&i.value))
    }

    /// Whether switch `name` is on.
    pub fn is_on(&self, name: &str) -> Option<bool> {
        self.item(name).map(|i| i.value.trim() == "On")
    }
}

/// An INDI number: decimal, or sexagesimal `d:m:s` / `d:m`.
pub fn parse_number(text: &str) -> Option<f64> {
    let t = text.trim();
    if let Ok(x) = t.parse::<f64>() {
        return x.is_finite().then_some(x);
    }
    let parts: Vec<&str> = t.split([':', ' ']).filter(|p| !p.is_empty()).collect();
    if parts.len() < 2 || parts.len() > 3 {
        return None;
    }
    let negative = parts[0].starts_with('-');
    let mut value = 0.0;
    for (k, p) in parts.iter().enumerate() {
        let v: f64 = p.trim_start_matches('-').parse().ok()?;
        value += v / 60f64.powi(k as i32);
    }
    Some(if negative { -value } else { value })
}

/// An image (or other BLOB) a device sent.
#[derive(Debug, Clone, PartialEq)]
pub struct Blob {
    /// The device.
    pub device: String,
    /// The property, e.g. `CCD1`.
    pub property: String,
    /// The element.
    pub element: String,
    /// Its format, e.g. `.fits`.
    pub format: String,
    /// Its bytes, base64-decoded.
    pub bytes: Vec<u8>,
}

/// The mirror of the server's devices, kept by the reading task.
#[derive(Debug, Default)]
pub struct Mirror {
    /// Every property, by (device, property name).
    pub properties: BTreeMap<(String, String), Property>,
    /// BLOBs received and not yet taken.
    pub blobs: VecDeque<Blob>,
    /// The devices' latest messages (device, text), newest last, at most 32.
    pub messages: VecDeque<(String, String)>,
    /// Why the connection ended, once it has.
    pub closed: Option<String>,
    /// Elements read so far.
    pub read: u64,
}

impl Mirror {
    /// The property `name` of `device`.
    pub fn property(&self, device: &str, name: &str) -> Option<&Property> {
        self.properties.get(&(device.to_owned(), name.to_owned()))
    }

    /// The latest message of `device`, if any.
    pub fn last_message(&self, device: &str) -> Option<&str> {
        self.messages
            .iter()
            .rev()
            .find(|(d, _)| d == device)
            .map(|(_, m)| m.as_str())
    }

    fn apply(&mut self, el: Element) {
        self.read += 1;
        let device = el.attr("device").unwrap_or_default().to_owned();
        let name = el.attr("name").unwrap_or_default().to_owned();
        if let Some(text) = el.attr("message")
            && !text.is_empty()
        {
            tracing::debug!(device = %device, "INDI: {text}");
            self.messages.push_back((device.clone(), text.to_owned()));
            while self.messages.len() > 32 {
                self.messages.pop_front();
            }
        }
        let tag = el.name.as_str();
        if let Some(kind) = tag
            .strip_prefix("def")
            .and_then(|k| k.strip_suffix("Vector"))
            .and_then(kind_of)
        {
            let items = el
                .children
                .iter()
                .map(|c| Item {
                    name: c.attr("name").unwrap_or_default().to_owned(),
                    label: c.attr("label").unwrap_or_default().to_owned(),
                    value: c.text.trim().to_owned(),
                    min: c.number_attr("min"),
                    max: c.number_attr("max"),
                    step: c.number_attr("step"),
                })
                .collect();
            let property = Property {
                device: device.clone(),
                name: name.clone(),
                kind,
                state: PropertyState::parse(el.attr("state")).unwrap_or(PropertyState::Idle),
                perm: el.attr("perm").unwrap_or("ro").to_owned(),
                items,
                updated: self.read,
            };
            self.properties.insert((device, name), property);
        } else if tag.starts_with("set") && tag.ends_with("Vector") {
            if tag == "setBLOBVector" {
                for c in &el.children {
                    let cleaned: Vec<u8> = c.text.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
                    match base64::engine::general_purpose::STANDARD.decode(&cleaned) {
                        Ok(bytes) if !bytes.is_empty() => self.blobs.push_back(Blob {
                            device: device.clone(),
                            property: name.clone(),
                            element: c.attr("name").unwrap_or_default().to_owned(),
                            format: c.attr("format").unwrap_or_default().to_owned(),
                            bytes,
                        }),
                        Ok(_) => {}
                        Err(e) => tracing::warn!(device = %device, property = %name, "INDI BLOB is not base64: {e}"),
                    }
                }
            }
            let Some(p) = self.properties.get_mut(&(device, name)) else {
                return;
            };
            p.updated = self.read;
            if let Some(state) = PropertyState::parse(el.attr("state")) {
                p.state = state;
            }
            if p.kind == PropertyKind::Blob {
                return;
            }
            for c in &el.children {
                let item_name = c.attr("name").unwrap_or_default();
                if let Some(item) = p.items.iter_mut().find(|i| i.name == item_name) {
                    item.value = c.text.trim().to_owned();
                    for (field, key) in [(&mut item.min, "min"), (&mut item.max, "max"), (&mut item.step, "step")] {
                        if let Some(v) = c.number_attr(key) {
                            *field = Some(v);
                        }
                    }
                }
            }
        } else if tag == "delProperty" {
            if name.is_empty() {
                self.properties.retain(|(d, _), _| *d != device);
            } else {
                self.properties.remove(&(device, name));
            }
        }
    }
}

fn kind_of(k: &str) -> Option<PropertyKind> {
    Some(match k {
        "Number" => PropertyKind::Number,
        "Switch" => PropertyKind::Switch,
        "Text" => PropertyKind::Text,
        "Light" => PropertyKind::Light,
        "BLOB" => PropertyKind::Blob,
        _ => return None,
    })
}

struct Shared {
    mirror: Mutex<Mirror>,
    changed: watch::Sender<u64>,
}

impl Shared {
    fn lock(&self) -> std::sync::MutexGuard<'_, Mirror> {
        self.mirror.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    fn bump(&self) {
        self.changed.send_modify(|n| *n = n.wrapping_add(1));
    }
}

/// A connection to an INDI server.
pub struct IndiClient {
    server: String,
    writer: tokio::sync::Mutex<OwnedWriteHalf>,
    shared: Arc<Shared>,
    reader: JoinHandle<()>,
}

impl std::fmt::Debug for IndiClient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IndiClient")
            .field("server", &self.server)
            .finish_non_exhaustive()
    }
}

impl Drop for IndiClient {
    fn drop(&mut self) {
        self.reader.abort();
    }
}

/// How long the server has to answer a connection or a property request.
pub const ANSWER_TIMEOUT: Duration = Duration::from_secs(15);

fn link_error(server: &str, what: &str, e: impl std::fmt::Display) -> DeviceError {
    DeviceError::Link(DriverError::Io(io::Error::new(
        io::ErrorKind::ConnectionAborted,
        format!("INDI server {server}: {what}: {e}"),
    )))
}

impl IndiClient {
    /// Connects to the INDI server at `server` (`host:port`) and asks for
    /// every device's properties.
    pub async fn connect(server: &str) -> Result<Self, DeviceError> {
        let stream = tokio::time::timeout(ANSWER_TIMEOUT, TcpStream::connect(server))
            .await
            .map_err(|_| DeviceError::Timeout(format!("connecting to INDI server {server}")))?
            .map_err(|e| link_error(server, "cannot connect", e))?;
        let _ = stream.set_nodelay(true);
        let (read, write) = stream.into_split();
        let (changed, _) = watch::channel(0);
        let shared = Arc::new(Shared {
            mirror: Mutex::new(Mirror::default()),
            changed,
        });
        let task_shared = shared.clone();
        let reader = tokio::spawn(async move {
            let mut elements = ElementReader::new(read);
            let why = loop {
                match elements.next().await {
                    Ok(Some(el)) => {
                        task_shared.lock().apply(el);
                        task_shared.bump();
                    }
                    Ok(None) => break "the server closed the connection".to_owned(),
                    Err(e) => break e.to_string(),
                }
            };
            tracing::warn!("INDI connection ended: {why}");
            task_shared.lock().closed = Some(why);
            task_shared.bump();
        });
        let client = IndiClient {
            server: server.to_owned(),
            writer: tokio::sync::Mutex::new(write),
            shared,
            reader,
        };
        client.send(&element::get_properties(None)).await?;
        Ok(client)
    }

    /// The server's address.
    pub fn server(&self) -> &str {
        &self.server
    }

    /// Writes `xml` to the server.
    pub async fn send(&self, xml: &str) -> Result<(), DeviceError> {
        let mut w = self.writer.lock().await;
        w.write_all(xml.as_bytes())
            .await
            .map_err(|e| link_error(&self.server, "writing", e))?;
        w.flush().await.map_err(|e| link_error(&self.server, "writing", e))
    }

    /// Runs `f` on the mirror of the server's devices.
    pub fn with<T>(&self, f: impl FnOnce(&mut Mirror) -> T) -> T {
        f(&mut self.shared.lock())
    }

    /// The property `name` of `device`, as last reported.
    pub fn property(&self, device: &str, name: &str) -> Option<Property> {
        self.with(|m| m.property(device, name).cloned())
    }

    /// The devices the server has defined properties for, in order.
    pub fn devices(&self) -> Vec<String> {
        self.with(|m| {
            let mut d: Vec<String> = m.properties.keys().map(|(d, _)| d.clone()).collect();
            d.dedup();
            d
        })
    }

    /// Waits until `f` finds what it looks for in the mirror (`Some`), for at
    /// most `timeout`; `what` names it in the timeout's message. A connection
    /// that ends meanwhile is a link error.
    pub async fn wait_for<T>(
        &self,
        what: &str,
        timeout: Duration,
        mut f: impl FnMut(&mut Mirror) -> Result<Option<T>, DeviceError>,
    ) -> Result<T, DeviceError> {
        let mut changes = self.shared.changed.subscribe();
        let deadline = tokio::time::Instant::now() + timeout;
        loop {
            changes.borrow_and_update();
            {
                let mut m = self.shared.lock();
                if let Some(v) = f(&mut m)? {
                    return Ok(v);
                }
                if let Some(why) = &m.closed {
                    return Err(link_error(&self.server, what, why));
                }
            }
            match tokio::time::timeout_at(deadline, changes.changed()).await {
                Err(_) => {
                    return Err(DeviceError::Timeout(format!(
                        "INDI server {}: {what} (waited {:.0} s)",
                        self.server,
                        timeout.as_secs_f64()
                    )));
                }
                Ok(Err(_)) => return Err(link_error(&self.server, what, "the connection ended")),
                Ok(Ok(())) => {}
            }
        }
    }

    /// Waits until the server has said nothing new for `quiet` (it has
    /// listed what it has: INDI marks no end of a listing), or for at most
    /// `limit`.
    pub async fn settled(&self, quiet: Duration, limit: Duration) {
        let deadline = tokio::time::Instant::now() + limit;
        let mut last = u64::MAX;
        while tokio::time::Instant::now() < deadline {
            let read = self.with(|m| m.read);
            if read == last && read > 0 {
                return;
            }
            last = read;
            tokio::time::sleep(quiet).await;
        }
    }

    /// Waits for `device` to define property `name`.
    pub async fn defined(&self, device: &str, name: &str) -> Result<Property, DeviceError> {
        let what = format!("device {device:?} defining {name}");
        self.wait_for(&what, ANSWER_TIMEOUT, |m| Ok(m.property(device, name).cloned()))
            .await
    }

    /// `device`'s property `name` as the device states it now: asked anew
    /// and answered after everything the device was asked before (the
    /// driver answers in order), so values it changes on connecting are
    /// there.
    pub async fn fresh(&self, device: &str, name: &str) -> Result<Property, DeviceError> {
        let asked = self.with(|m| m.read);
        self.send(&format!(
            "<getProperties version=\"1.7\" device=\"{}\" name=\"{}\"/>\n",
            quick_xml::escape::escape(device),
            quick_xml::escape::escape(name)
        ))
        .await?;
        self.wait_for(&format!("{device:?} restating {name}"), ANSWER_TIMEOUT, |m| {
            Ok(m.property(device, name).filter(|p| p.updated > asked).cloned())
        })
        .await
    }

    /// Connects `device` (its `CONNECTION` switch to `CONNECT`), waiting
    /// until it reports itself connected.
    pub async fn connect_device(&self, device: &str) -> Result<(), DeviceError> {
        let p = self.defined(device, "CONNECTION").await.map_err(|e| match e {
            DeviceError::Timeout(_) => DeviceError::Camera(format!(
                "INDI server {} has no device {device:?} (it offers: {})",
                self.server,
                self.devices().join(", ")
            )),
            other => other,
        })?;
        if p.is_on("CONNECT") == Some(true) && p.state == PropertyState::Ok {
            return Ok(());
        }
        self.send(&element::new_vector(
            "Switch",
            device,
            "CONNECTION",
            &[("CONNECT", "On".into())],
        ))
        .await?;
        self.wait_for(&format!("connecting {device:?}"), ANSWER_TIMEOUT, |m| {
            let Some(p) = m.property(device, "CONNECTION") else {
                return Ok(None);
            };
            match (p.is_on("CONNECT"), p.state) {
                (_, PropertyState::Alert) => Err(DeviceError::Camera(format!(
                    "INDI device {device:?} refused to connect: {}",
                    m.last_message(device).unwrap_or("no message")
                ))),
                (Some(true), PropertyState::Ok | PropertyState::Idle) => Ok(Some(())),
                _ => Ok(None),
            }
        })
        .await
    }

    /// Asks `device`'s number property `name` for `items`.
    pub async fn set_numbers(&self, device: &str, name: &str, items: &[(&str, f64)]) -> Result<(), DeviceError> {
        let items: Vec<(&str, String)> = items.iter().map(|(k, v)| (*k, format!("{v}"))).collect();
        self.send(&element::new_vector("Number", device, name, &items)).await
    }

    /// Turns on `device`'s switch `item` of property `name` (one-of-many
    /// switches turn the others off themselves).
    pub async fn switch_on(&self, device: &str, name: &str, item: &str) -> Result<(), DeviceError> {
        self.send(&element::new_vector("Switch", device, name, &[(item, "On".into())]))
            .await
    }

    /// Asks the server to send `device`'s BLOBs along with its properties.
    pub async fn enable_blobs(&self, device: &str) -> Result<(), DeviceError> {
        self.send(&element::enable_blob(device)).await
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn el(xml: &str) -> Element {
        let rt = tokio::runtime::Builder::new_current_thread().build().unwrap();
        rt.block_on(async { ElementReader::new(xml.as_bytes()).next().await.unwrap().unwrap() })
    }

    #[test]
    fn the_mirror_follows_definitions_changes_blobs_and_deletions() {
        let mut m = Mirror::default();
        m.apply(el(r#"<defNumberVector device="C" name="CCD_EXPOSURE" state="Idle" perm="rw"><defNumber name="CCD_EXPOSURE_VALUE" min="0.001" max="3600" step="0.001">1</defNumber></defNumberVector>"#));
        let p = m.property("C", "CCD_EXPOSURE").unwrap();
        assert_eq!(
            (p.kind, p.state, p.number("CCD_EXPOSURE_VALUE")),
            (PropertyKind::Number, PropertyState::Idle, Some(1.0))
        );
        assert_eq!(p.item("CCD_EXPOSURE_VALUE").unwrap().max, Some(3600.0));
        m.apply(el(r#"<setNumberVector device="C" name="CCD_EXPOSURE" state="Busy" message="exposing"><oneNumber name="CCD_EXPOSURE_VALUE">0.25</oneNumber></setNumberVector>"#));
        let p = m.property("C", "CCD_EXPOSURE").unwrap();
        assert_eq!(
            (p.state, p.number("CCD_EXPOSURE_VALUE")),
            (PropertyState::Busy, Some(0.25))
        );
        assert_eq!(m.last_message("C"), Some("exposing"));
        m.apply(el(r#"<setBLOBVector device="C" name="CCD1" state="Ok"><oneBLOB name="CCD1" size="3" format=".fits">QUJD</oneBLOB></setBLOBVector>"#));
        let b = m.blobs.pop_front().unwrap();
        assert_eq!(
            (
                b.device.as_str(),
                b.property.as_str(),
                b.format.as_str(),
                b.bytes.as_slice()
            ),
            ("C", "CCD1", ".fits", &b"ABC"[..])
        );
        m.apply(el(r#"<delProperty device="C" name="CCD_EXPOSURE"/>"#));
        assert!(m.property("C", "CCD_EXPOSURE").is_none());
    }

    #[test]
    fn numbers_read_decimal_and_sexagesimal() {
        assert_eq!(parse_number(" 3600 "), Some(3600.0));
        assert_eq!(parse_number("12:30:00"), Some(12.5));
        assert_eq!(parse_number("-10:30"), Some(-10.5));
        assert_eq!(parse_number("nan"), None);
        assert_eq!(parse_number("On"), None);
    }
}
