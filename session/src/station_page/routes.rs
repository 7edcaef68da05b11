//! The HTTP routes (see the table in [`super`]). Every handler only reads;
//! a day is named by a plain `YYYY-MM-DD` ([`parse_day`]) and the files
//! served are fixed names under that day's directory, so no request can
//! reach another file. Bad requests get 400, unknown routes and days 404,
//! a missing or wrong token 401.

use std::path::PathBuf;
use std::sync::Arc;

use axum::Router;
use axum::extract::{Path, Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use campanile_capture::store::PROCESSED_DIR;
use campanile_capture::unattended::day_rollover::day_dir;
use chrono::NaiveDate;
use tokio::sync::{Mutex, watch};

use super::access::carries_token;
use super::preview::frame_preview_png;
use super::store_reader::{DayView, KEOGRAM_FILE, day_view, parse_day};
use super::store_watch::{Published, events};

/// The page: HTML with its style and script inline.
pub const PAGE_HTML: &str = include_str!("page.html");

/// What the handlers share.
pub struct PageState {
    store: PathBuf,
    token: Option<String>,
    /// The latest snapshot (see [`super::store_watch`]).
    pub snapshot: watch::Receiver<Arc<Published>>,
    /// The last preview made: its day and frame key, and the PNG. One is
    /// made at a time, whatever the number of clients.
    preview: Mutex<Option<(String, Arc<Vec<u8>>)>>,
}

impl PageState {
    /// The state of a server on `store`.
    pub fn new(store: PathBuf, token: Option<String>, snapshot: watch::Receiver<Arc<Published>>) -> Self {
        Self {
            store,
            token,
            snapshot,
            preview: Mutex::new(None),
        }
    }
}

/// The router of every route.
pub fn router(state: Arc<PageState>) -> Router {
    Router::new()
        .route("/", get(page))
        .route("/api/state", get(api_state))
        .route("/api/days", get(api_days))
        .route("/api/day/{day}", get(api_day))
        .route("/day/{day}/keogram.png", get(keogram))
        .route("/day/{day}/latest.png", get(latest))
        .route("/events", get(events))
        .fallback(not_found)
        .layer(middleware::from_fn_with_state(state.clone(), require_token))
        .with_state(state)
}

fn error(status: StatusCode, message: String) -> Response {
    (
        status,
        [(header::CONTENT_TYPE, "text/plain; charset=utf-8")],
        message + "\n",
    )
        .into_response()
}

fn json(body: String) -> Response {
    (
        [
            (header::CONTENT_TYPE, "application/json"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        body,
    )
        .into_response()
}

fn png(bytes: Vec<u8>) -> Response {
    (
        [(header::CONTENT_TYPE, "image/png"), (header::CACHE_CONTROL, "no-cache")],
        bytes,
    )
        .into_response()
}

async fn require_token(State(state): State<Arc<PageState>>, request: Request, next: Next) -> Response {
    if let Some(token) = &state.token {
        let auth = request.headers().get(header::AUTHORIZATION).map(HeaderValue::as_bytes);
        if !carries_token(token, auth, request.uri().query()) {
            let mut r = error(
                StatusCode::UNAUTHORIZED,
                "401: this page needs its token: open it as /?token=TOKEN, or send `Authorization: Bearer TOKEN`"
                    .to_owned(),
            );
            r.headers_mut()
                .insert(header::WWW_AUTHENTICATE, HeaderValue::from_static("Bearer"));
            return r;
        }
    }
    let mut response = next.run(request).await;
    response
        .headers_mut()
        .insert("x-content-type-options", HeaderValue::from_static("nosniff"));
    response
}

async fn not_found(request: Request) -> Response {
    error(
        StatusCode::NOT_FOUND,
        format!(
            "404: no such page: {} (see / for the page, /api/state for the data)",
            request.uri().path()
        ),
    )
}

async fn page() -> Response {
    (
        [
            (header::CONTENT_TYPE, "text/html; charset=utf-8"),
            (header::CACHE_CONTROL, "no-cache"),
        ],
        PAGE_HTML,
    )
        .into_response()
}

async fn api_state(State(state): State<Arc<PageState>>) -> Response {
    let published = state.snapshot.borrow().clone();
    json(published.json.clone())
}

async fn api_days(State(state): State<Arc<PageState>>) -> Response {
    let published = state.snapshot.borrow().clone();
    json(serde_json::to_string(&published.snapshot.days).unwrap_or_else(|_| "[]".into()))
}

/// A request refused: its status and message (a response by [`refused`]).
type Refusal = (StatusCode, String);

fn refused((status, message): Refusal) -> Response {
    error(status, message)
}

/// The day a request names, which must be a day of the store.
fn known_day(state: &PageState, text: &str) -> Result<NaiveDate, Refusal> {
    let day = parse_day(text).ok_or_else(|| {
        (
            StatusCode::BAD_REQUEST,
            format!("400: day {text:?}: expected a date YYYY-MM-DD"),
        )
    })?;
    let published = state.snapshot.borrow().clone();
    let listed = published.snapshot.days.contains(&day)
        || published.snapshot.day.as_ref().is_some_and(|d| d.date == day)
        || day_dir(&state.store, day).is_dir();
    if listed {
        Ok(day)
    } else {
        Err((StatusCode::NOT_FOUND, format!("404: the store has no day {day}")))
    }
}

/// The day's view: the published one for the current day, else read now.
async fn view_of(state: &Arc<PageState>, day: NaiveDate) -> Result<DayView, Refusal> {
    let published = state.snapshot.borrow().clone();
    if let Some(v) = published.snapshot.day.as_ref().filter(|d| d.date == day) {
        return Ok(v.clone());
    }
    let store = state.store.clone();
    tokio::task::spawn_blocking(move || day_view(&store, day))
        .await
        .map_err(|e| {
            (
                StatusCode::INTERNAL_SERVER_ERROR,
                format!("500: reading day {day}: {e}"),
            )
        })
}

async fn api_day(State(state): State<Arc<PageState>>, Path(day): Path<String>) -> Response {
    let day = match known_day(&state, &day) {
        Ok(d) => d,
        Err(r) => return refused(r),
    };
    match view_of(&state, day).await {
        Ok(v) => json(serde_json::to_string(&v).unwrap_or_else(|_| "{}".into())),
        Err(r) => refused(r),
    }
}

async fn keogram(State(state): State<Arc<PageState>>, Path(day): Path<String>) -> Response {
    let day = match known_day(&state, &day) {
        Ok(d) => d,
        Err(r) => return refused(r),
    };
    let path = day_dir(&state.store, day).join(PROCESSED_DIR).join(KEOGRAM_FILE);
    match tokio::fs::read(&path).await {
        Ok(bytes) => png(bytes),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => error(
            StatusCode::NOT_FOUND,
            format!(
                "404: day {day} has no keogram yet (it is written when the station processes a scan: `station run --process`)"
            ),
        ),
        Err(e) => error(
            StatusCode::INTERNAL_SERVER_ERROR,
            format!("500: {}: {e}", path.display()),
        ),
    }
}

async fn latest(State(state): State<Arc<PageState>>, Path(day): Path<String>) -> Response {
    let day = match known_day(&state, &day) {
        Ok(d) => d,
        Err(r) => return refused(r),
    };
    let view = match view_of(&state, day).await {
        Ok(v) => v,
        Err(r) => return refused(r),
    };
    let Some(frame) = view.latest_sky_frame else {
        return error(
            StatusCode::NOT_FOUND,
            format!("404: day {day} has no sky frame on disk"),
        );
    };
    let id = format!("{day}/{}", frame.key);
    let mut cache = state.preview.lock().await;
    if let Some((key, bytes)) = cache.as_ref()
        && *key == id
    {
        return png(bytes.as_ref().clone());
    }
    let dir = day_dir(&state.store, day);
    let made = tokio::task::spawn_blocking(move || frame_preview_png(&dir, &frame.entry)).await;
    match made {
        Ok(Ok(bytes)) => {
            let bytes = Arc::new(bytes);
            *cache = Some((id, bytes.clone()));
            png(bytes.as_ref().clone())
        }
        // Pruned or rewritten between the listing and now, or unreadable.
        Ok(Err(e)) => error(StatusCode::NOT_FOUND, format!("404: day {day}'s latest sky frame: {e}")),
        Err(e) => error(StatusCode::INTERNAL_SERVER_ERROR, format!("500: {e}")),
    }
}
