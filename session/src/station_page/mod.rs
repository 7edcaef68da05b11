//! The station's live page (`campanile station serve`): a read-only web
//! page and JSON API of what an unattended station is doing, pushed to
//! the browser by server-sent events.
//!
//! The page reads only the files the station writes (the heartbeat, the
//! day's journal and processed products), polled by their sizes and
//! modification times; the station is never asked anything, so clients
//! cannot slow it. One snapshot is built per change and shared by every
//! client.
//!
//! - [`store_reader`]: what is read from the store, and the snapshot;
//! - [`store_watch`]: the polling of the store and the event stream;
//! - [`preview`]: the latest sky frame as a PNG for the page;
//! - [`access`]: the loopback rule and the token;
//! - [`routes`]: the HTTP routes (the page, `/api/…`, `/events`).
//!
//! Routes (all `GET`; with a token, every route needs it):
//!
//! | Route | What |
//! | --- | --- |
//! | `/` | the page (HTML and its script, no external files) |
//! | `/api/state` | the snapshot: heartbeat, days, the current day |
//! | `/api/days` | the store's days, oldest first |
//! | `/api/day/YYYY-MM-DD` | one day: frames, scans, latest sky frame, outages, missed shots, sky series columns, extinction |
//! | `/day/YYYY-MM-DD/keogram.png` | the day's keogram as the station's processing wrote it |
//! | `/day/YYYY-MM-DD/latest.png` | the day's latest sky frame, stretched to 8 bits |
//! | `/events` | server-sent events: `state`, the snapshot, at once and on every change |

pub mod access;
pub mod preview;
pub mod routes;
pub mod store_reader;
pub mod store_watch;

use std::future::Future;
use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use crate::Result;

/// How the page is served.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The station's store (`station run --store DIR`).
    pub store: PathBuf,
    /// Where to listen; a non-loopback address needs a token.
    pub listen: SocketAddr,
    /// The token every request must carry (`Authorization: Bearer TOKEN`
    /// or `?token=TOKEN`), if any.
    pub token: Option<String>,
    /// How often the store's files are looked at.
    pub poll: Duration,
}

/// A bound server, not yet serving.
pub struct PageServer {
    listener: tokio::net::TcpListener,
    state: Arc<routes::PageState>,
    watcher: tokio::task::JoinHandle<()>,
}

impl PageServer {
    /// Checks the options, reads the store once and binds the address.
    pub async fn bind(options: ServeOptions) -> Result<PageServer> {
        access::check(&options)?;
        let (snapshot, watcher) = store_watch::watch_store(options.store.clone(), options.poll).await;
        let listener = tokio::net::TcpListener::bind(options.listen)
            .await
            .map_err(|e| anyhow::anyhow!("--listen {}: cannot listen there: {e}", options.listen))?;
        let state = Arc::new(routes::PageState::new(options.store, options.token, snapshot));
        Ok(PageServer {
            listener,
            state,
            watcher,
        })
    }

    /// The address it listens on (the port chosen when asked for port 0).
    pub fn local_addr(&self) -> Result<SocketAddr> {
        Ok(self.listener.local_addr()?)
    }

    /// Serves until `shutdown` completes; the event streams end with it.
    pub async fn run(self, shutdown: impl Future<Output = ()> + Send + 'static) -> Result<()> {
        let PageServer {
            listener,
            state,
            watcher,
        } = self;
        let abort = watcher.abort_handle();
        axum::serve(listener, routes::router(state))
            .with_graceful_shutdown(async move {
                shutdown.await;
                // The watcher holds the events' sender: stopping it ends
                // every open event stream, so the shutdown does not wait
                // for browsers to leave.
                abort.abort();
            })
            .await?;
        watcher.abort();
        Ok(())
    }
}

/// `campanile station serve`: serves the page until SIGINT or SIGTERM,
/// after writing the address to `out`.
pub fn serve(options: ServeOptions, out: &mut dyn Write) -> Result<()> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    runtime.block_on(async {
        let store = options.store.clone();
        let with_token = options.token.is_some();
        let server = PageServer::bind(options).await?;
        let addr = server.local_addr()?;
        writeln!(
            out,
            "serving the station in {} at http://{addr}/{}",
            store.display(),
            if with_token { "?token=…" } else { "" }
        )?;
        out.flush()?;
        server.run(stop_signal()).await
    })
}

/// SIGINT or SIGTERM.
async fn stop_signal() {
    use tokio::signal::unix::{SignalKind, signal};
    match signal(SignalKind::terminate()) {
        Ok(mut term) => {
            tokio::select! {
                _ = tokio::signal::ctrl_c() => {}
                _ = term.recv() => {}
            }
        }
        Err(_) => {
            let _ = tokio::signal::ctrl_c().await;
        }
    }
}

#[cfg(test)]
mod server_tests;
