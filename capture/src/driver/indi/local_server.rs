//! An `indiserver` of INDI's own (Debian's `indi-bin`) run by this
//! process on a free loopback port with the drivers asked for, and stopped
//! by its PID when dropped: how the tests meet real INDI software, and how
//! a user can try a station on INDI's simulators.

use std::collections::BTreeSet;
use std::net::TcpListener;
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The ports [`LocalServer::start`] has handed out in this process.
static HANDED_OUT: Mutex<BTreeSet<u16>> = Mutex::new(BTreeSet::new());

/// Why [`LocalServer::launch`] failed.
enum StartError {
    /// The server exited on start: another process holds the port.
    Exited(String),
    /// Anything else.
    Other(String),
}

/// A running `indiserver`, killed (by PID) and reaped on drop.
#[derive(Debug)]
pub struct LocalServer {
    child: Option<Child>,
    port: u16,
}

impl LocalServer {
    /// Starts `indiserver` with `drivers` (e.g. `indi_simulator_ccd`) on a
    /// free loopback port, waiting until it listens.
    ///
    /// The port is one the system reports free and that no other server
    /// of this process has had: a port is free again once its server is
    /// stopped, and a test that stops a server and starts it again on the
    /// same port (`start_on`) would otherwise race a server started
    /// meanwhile on that port. If the server still exits on start (another
    /// process took the port between the check and its bind), another
    /// port is tried, three times at most.
    pub fn start(drivers: &[&str]) -> Result<LocalServer, String> {
        let mut last = String::new();
        for _ in 0..3 {
            let port = loop {
                let port = TcpListener::bind("127.0.0.1:0")
                    .and_then(|l| l.local_addr())
                    .map_err(|e| format!("finding a free port: {e}"))?
                    .port();
                let mut handed_out = HANDED_OUT.lock().unwrap_or_else(|e| e.into_inner());
                if handed_out.insert(port) {
                    break port;
                }
            };
            match LocalServer::launch(port, drivers) {
                Ok(server) => return Ok(server),
                Err(StartError::Exited(e)) => last = e,
                Err(StartError::Other(e)) => return Err(e),
            }
        }
        Err(last)
    }

    /// Starts `indiserver` with `drivers` on `port`.
    pub fn start_on(port: u16, drivers: &[&str]) -> Result<LocalServer, String> {
        LocalServer::launch(port, drivers).map_err(|e| match e {
            StartError::Exited(e) | StartError::Other(e) => e,
        })
    }

    /// [`LocalServer::start_on`], telling a server that exited on start
    /// (its port taken) from the other failures.
    fn launch(port: u16, drivers: &[&str]) -> Result<LocalServer, StartError> {
        // Its own local (abstract) socket too: every indiserver binds
        // /tmp/indiserver by default, so a second one would exit at once.
        let child = Command::new("indiserver")
            .arg("-p")
            .arg(port.to_string())
            .arg("-u")
            .arg(format!("/tmp/campanile-indiserver-{port}"))
            .args(drivers)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| {
                StartError::Other(format!(
                    "cannot start indiserver ({e}): INDI's server and simulators come with Debian's indi-bin \
                     (`sudo apt-get install indi-bin`; .ci/run installs it)"
                ))
            })?;
        let mut server = LocalServer {
            child: Some(child),
            port,
        };
        let deadline = Instant::now() + Duration::from_secs(15);
        let exited = |server: &mut LocalServer| match server.child.as_mut().map(Child::try_wait) {
            Some(Ok(Some(status))) => Some(StartError::Exited(format!(
                "indiserver on port {port} exited at once ({status})"
            ))),
            _ => None,
        };
        while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
            if let Some(e) = exited(&mut server) {
                return Err(e);
            }
            if Instant::now() > deadline {
                return Err(StartError::Other(format!(
                    "indiserver did not listen on port {port} within 15 s"
                )));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        // Something listens; it must be this server, not one that held the
        // port before (this one would then exit on its failed bind).
        std::thread::sleep(Duration::from_millis(100));
        if let Some(e) = exited(&mut server) {
            return Err(e);
        }
        Ok(server)
    }

    /// Its port.
    pub fn port(&self) -> u16 {
        self.port
    }

    /// Its address, `127.0.0.1:PORT`.
    pub fn address(&self) -> String {
        format!("127.0.0.1:{}", self.port)
    }

    /// Its process id.
    pub fn pid(&self) -> Option<u32> {
        self.child.as_ref().map(Child::id)
    }

    /// Kills the server (and so its drivers' pipes) and reaps it.
    pub fn stop(&mut self) {
        if let Some(mut child) = self.child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

impl Drop for LocalServer {
    fn drop(&mut self) {
        self.stop();
    }
}
