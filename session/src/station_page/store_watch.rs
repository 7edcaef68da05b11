//! The store watched by polling: every poll interval the sizes and
//! modification times of the few files the page shows are compared with
//! the last ones; on a change one snapshot is built and published to
//! every client (the JSON API and the event streams share it).

use std::convert::Infallible;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use axum::extract::State;
use axum::response::sse::{Event, KeepAlive, Sse};
use futures_util::Stream;
use tokio::sync::watch;

use super::routes::PageState;
use super::store_reader::{StationSnapshot, snapshot, store_stamp};

/// A snapshot as published: its number (1, 2, …) and its JSON.
#[derive(Debug)]
pub struct Published {
    /// Increases by one at every change of the store seen.
    pub version: u64,
    /// The snapshot.
    pub snapshot: StationSnapshot,
    /// The snapshot as JSON (what `/api/state` and `/events` send).
    pub json: String,
}

fn publish(version: u64, snapshot: StationSnapshot) -> Arc<Published> {
    // Plain data with string keys: serializing cannot fail; an empty
    // object would be shown as "no heartbeat" rather than a panic.
    let json = serde_json::to_string(&snapshot).unwrap_or_else(|_| "{}".to_owned());
    Arc::new(Published {
        version,
        snapshot,
        json,
    })
}

/// Reads the store once, then polls it every `poll` in a task. The task
/// holds the sender: aborting it ends every event stream.
pub async fn watch_store(
    store: PathBuf,
    poll: Duration,
) -> (watch::Receiver<Arc<Published>>, tokio::task::JoinHandle<()>) {
    let read = |store: PathBuf| async move {
        tokio::task::spawn_blocking(move || (store_stamp(&store), snapshot(&store)))
            .await
            .ok()
    };
    let (mut stamp, first) = match read(store.clone()).await {
        Some(x) => x,
        None => (Vec::new(), snapshot(&store)),
    };
    let (tx, rx) = watch::channel(publish(1, first));
    let task = tokio::spawn(async move {
        let mut version = 1;
        let mut ticks = tokio::time::interval(poll);
        ticks.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        loop {
            ticks.tick().await;
            let s = store.clone();
            let Ok(now) = tokio::task::spawn_blocking(move || store_stamp(&s)).await else {
                continue;
            };
            if now == stamp {
                continue;
            }
            let Some((now, snap)) = read(store.clone()).await else {
                continue;
            };
            stamp = now;
            version += 1;
            if tx.send(publish(version, snap)).is_err() {
                return;
            }
        }
    });
    (rx, task)
}

/// `GET /events`: the snapshot as a `state` event at once, then at every
/// change; a comment every 15 s keeps idle connections open.
pub async fn events(State(state): State<Arc<PageState>>) -> Sse<impl Stream<Item = Result<Event, Infallible>>> {
    let rx = state.snapshot.clone();
    let stream = futures_util::stream::unfold((rx, true), |(mut rx, first)| async move {
        if !first && rx.changed().await.is_err() {
            return None;
        }
        let p = rx.borrow_and_update().clone();
        let event = Event::default()
            .event("state")
            .id(p.version.to_string())
            .data(p.json.as_str());
        Some((Ok(event), (rx, false)))
    });
    Sse::new(stream).keep_alive(KeepAlive::default())
}
