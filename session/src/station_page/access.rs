//! Who may read the page: anyone on this computer when it listens on a
//! loopback address; on any other address only requests that carry the
//! token (`Authorization: Bearer TOKEN`, or `?token=TOKEN` for the
//! browser's page, images and event stream, which cannot set headers).

use std::path::Path;
use std::time::Duration;

use super::ServeOptions;
use crate::{Error, Result};

/// The shortest token accepted.
pub const MIN_TOKEN_CHARS: usize = 16;

/// Checks the options: the store is a directory, a non-loopback address
/// has a token, the token is long enough and printable, the poll interval
/// sane.
pub fn check(options: &ServeOptions) -> Result<()> {
    if !options.store.is_dir() {
        return Err(Error::input(format!(
            "{}: not a directory; expected a station's store (`station run --store DIR`)",
            options.store.display()
        )));
    }
    if let Some(token) = &options.token {
        check_token(token)?;
    } else if !options.listen.ip().is_loopback() {
        return Err(Error::input(format!(
            "--listen {}: not a loopback address; serving on a network needs --token or --token-file",
            options.listen
        )));
    }
    if !(Duration::from_millis(50)..=Duration::from_secs(60)).contains(&options.poll) {
        return Err(Error::input(format!(
            "--poll-ms: found {}; expected 50 to 60000 milliseconds",
            options.poll.as_millis()
        )));
    }
    Ok(())
}

fn check_token(token: &str) -> Result<()> {
    let chars = token.chars().count();
    if chars < MIN_TOKEN_CHARS || !token.chars().all(|c| c.is_ascii_graphic()) {
        return Err(Error::input(format!(
            "the token: found {chars} characters; expected {MIN_TOKEN_CHARS} or more printable ASCII characters without spaces (e.g. from `openssl rand -hex 16`)"
        )));
    }
    Ok(())
}

/// The token in `path`'s first line (surrounding white space dropped).
pub fn token_from_file(path: &Path) -> Result<String> {
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::input(format!("--token-file {}: {e}", path.display())))?;
    let token = text.lines().next().unwrap_or_default().trim().to_owned();
    check_token(&token).map_err(|e| Error::input(format!("--token-file {}: {e}", path.display())))?;
    Ok(token)
}

/// Whether a request with this `Authorization` header and query string
/// carries `token`. Compared in time independent of where they differ.
pub fn carries_token(token: &str, authorization: Option<&[u8]>, query: Option<&str>) -> bool {
    let from_header = authorization
        .and_then(|h| h.strip_prefix(b"Bearer "))
        .is_some_and(|t| same(t, token.as_bytes()));
    let from_query = query.is_some_and(|q| {
        q.split('&').filter_map(|kv| kv.strip_prefix("token=")).any(|t| {
            let t: Vec<u8> = percent_encoding::percent_decode_str(t).collect();
            same(&t, token.as_bytes())
        })
    });
    from_header || from_query
}

fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOKEN: &str = "0123456789abcdef+/";

    fn options(listen: &str, token: Option<&str>) -> ServeOptions {
        ServeOptions {
            store: std::env::temp_dir(),
            listen: listen.parse().unwrap(),
            token: token.map(str::to_owned),
            poll: Duration::from_millis(500),
        }
    }

    #[test]
    fn a_network_address_needs_a_token() {
        check(&options("127.0.0.1:8080", None)).unwrap();
        check(&options("[::1]:8080", None)).unwrap();
        let e = check(&options("0.0.0.0:8080", None)).unwrap_err().to_string();
        assert!(e.contains("--listen 0.0.0.0:8080: not a loopback address"), "{e}");
        check(&options("0.0.0.0:8080", Some(TOKEN))).unwrap();
        let e = check(&options("0.0.0.0:8080", Some("short"))).unwrap_err().to_string();
        assert!(e.contains("found 5 characters; expected 16 or more"), "{e}");
        let e = check(&options("127.0.0.1:1", Some("with a space in it ok"))).unwrap_err();
        assert!(e.is_bad_input());
        let mut o = options("127.0.0.1:8080", None);
        o.store = o.store.join("no-such-store-here");
        assert!(check(&o).unwrap_err().to_string().contains("not a directory"));
    }

    #[test]
    fn the_token_is_taken_from_the_header_or_the_query() {
        assert!(carries_token(TOKEN, Some(b"Bearer 0123456789abcdef+/"), None));
        assert!(!carries_token(TOKEN, Some(b"Bearer 0123456789abcdef+"), None));
        assert!(!carries_token(TOKEN, Some(b"Basic 0123456789abcdef+/"), None));
        // In a query, + and / are percent-encoded by the page.
        assert!(carries_token(TOKEN, None, Some("v=3&token=0123456789abcdef%2B%2F")));
        assert!(!carries_token(TOKEN, None, Some("token=0123456789abcdeg%2B%2F")));
        assert!(!carries_token(TOKEN, None, Some("xtoken=0123456789abcdef%2B%2F")));
        assert!(!carries_token(TOKEN, None, None));
    }

    #[test]
    fn a_token_file_gives_its_first_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("token");
        std::fs::write(&path, format!("  {TOKEN}\nnot this\n")).unwrap();
        assert_eq!(token_from_file(&path).unwrap(), TOKEN);
        std::fs::write(&path, "\n").unwrap();
        assert!(
            token_from_file(&path)
                .unwrap_err()
                .to_string()
                .contains("found 0 characters")
        );
        let e = token_from_file(&dir.path().join("none")).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("--token-file"), "{e}");
    }
}
