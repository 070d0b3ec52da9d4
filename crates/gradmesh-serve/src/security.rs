//! What keeps other web pages and other users' requests away from the editor: the launch
//! token, the `Host` and `Origin` checks against DNS rebinding and cross-site requests, and the
//! resolution of file names inside the starting folder.

use std::path::{Component, Path, PathBuf};

use axum::extract::{Request, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

/// The secret a launch prints in its URL: 128 random bits as 32 hex digits.
pub fn new_token() -> String {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).expect("the operating system's random source");
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// What a request must match to be served.
#[derive(Clone, Debug)]
pub struct Gate {
    /// The launch token.
    pub token: String,
    /// The port the server listens on: `Host` must name it.
    pub port: u16,
}

impl Gate {
    /// Whether `host` (a `Host` header) names this server on the loopback address.
    pub fn host_allowed(&self, host: &str) -> bool {
        let Some((name, port)) = host.rsplit_once(':') else {
            return false;
        };
        port.parse::<u16>().ok() == Some(self.port) && is_loopback_name(name)
    }

    /// Whether `origin` (an `Origin` header) is a page of this server.
    pub fn origin_allowed(&self, origin: &str) -> bool {
        origin
            .strip_prefix("http://")
            .is_some_and(|host| self.host_allowed(host))
    }

    /// Whether `given` is the token, compared in time independent of where they differ.
    pub fn token_matches(&self, given: &str) -> bool {
        let (a, b) = (self.token.as_bytes(), given.as_bytes());
        a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
    }

    /// Why a request with `headers` and `query` must be refused, if it must.
    pub fn refusal(
        &self,
        headers: &HeaderMap,
        query: Option<&str>,
    ) -> Option<(StatusCode, String)> {
        let host = headers.get(header::HOST).and_then(|h| h.to_str().ok());
        if !host.is_some_and(|h| self.host_allowed(h)) {
            return Some((
                StatusCode::FORBIDDEN,
                "refused: the Host header does not name this server on 127.0.0.1".into(),
            ));
        }
        if let Some(origin) = headers.get(header::ORIGIN) {
            if !origin.to_str().is_ok_and(|o| self.origin_allowed(o)) {
                return Some((
                    StatusCode::FORBIDDEN,
                    "refused: the request comes from a page of another origin".into(),
                ));
            }
        }
        let token = headers
            .get("x-gradmesh-token")
            .and_then(|t| t.to_str().ok())
            .or_else(|| query.and_then(token_in_query));
        if !token.is_some_and(|t| self.token_matches(t)) {
            return Some((
                StatusCode::UNAUTHORIZED,
                "refused: the request lacks this launch's token (open the URL the server printed)"
                    .into(),
            ));
        }
        None
    }
}

fn is_loopback_name(name: &str) -> bool {
    name == "127.0.0.1" || name.eq_ignore_ascii_case("localhost")
}

/// The value of `token=` in a query string.
fn token_in_query(query: &str) -> Option<&str> {
    query
        .split('&')
        .find_map(|pair| pair.strip_prefix("token="))
}

/// Middleware refusing every request that [`Gate::refusal`] refuses.
pub async fn guard(State(gate): State<Gate>, request: Request, next: Next) -> Response {
    match gate.refusal(request.headers(), request.uri().query()) {
        Some(refusal) => refusal.into_response(),
        None => next.run(request).await,
    }
}

/// The folder the server may read and write documents in, and the resolution of names in it.
#[derive(Clone, Debug)]
pub struct Folder {
    /// The folder, canonical (symbolic links resolved).
    root: PathBuf,
}

impl Folder {
    /// The folder at `path`.
    pub fn new(path: &Path) -> std::io::Result<Folder> {
        Ok(Folder {
            root: path.canonicalize()?,
        })
    }

    /// The folder's canonical path.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The file named `name` (relative, `/`-separated) inside the folder, refusing names that
    /// leave it: absolute names, `..`, and symbolic links (of the file or of a folder on the
    /// way) that point outside. The file itself need not exist (for "save as"), but its folder
    /// must.
    pub fn resolve(&self, name: &str) -> Result<PathBuf, String> {
        let relative = Path::new(name);
        if name.is_empty() || name.contains('\0') {
            return Err("refused: an empty file name".into());
        }
        if !relative
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(format!(
                "refused: {name:?} is not a name inside the starting folder"
            ));
        }
        let joined = self.root.join(relative);
        let file_name = joined
            .file_name()
            .ok_or_else(|| format!("refused: {name:?} names no file"))?
            .to_owned();
        let parent = joined
            .parent()
            .and_then(|p| p.canonicalize().ok())
            .ok_or_else(|| format!("refused: the folder of {name:?} does not exist"))?;
        let path = parent.join(file_name);
        let real = match path.symlink_metadata() {
            Ok(_) => path
                .canonicalize()
                .map_err(|_| format!("refused: {name:?} is a link to nothing"))?,
            Err(_) => path,
        };
        if !real.starts_with(&self.root) {
            return Err(format!(
                "refused: {name:?} leads outside the starting folder"
            ));
        }
        Ok(real)
    }

    /// `path` (inside the folder) as a name relative to it, `/`-separated.
    pub fn name_of(&self, path: &Path) -> String {
        let relative = path.strip_prefix(&self.root).unwrap_or(path);
        relative
            .components()
            .map(|c| c.as_os_str().to_string_lossy())
            .collect::<Vec<_>>()
            .join("/")
    }

    /// The documents the editor can open: files with a known extension in the folder and its
    /// subfolders (to a depth of 3, not following links out of it), by name.
    pub fn documents(&self) -> Vec<String> {
        let mut names = Vec::new();
        self.collect_documents(&self.root, 0, &mut names);
        names.sort();
        names
    }

    fn collect_documents(&self, dir: &Path, depth: usize, names: &mut Vec<String>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten().take(10_000) {
            let Ok(real) = entry.path().canonicalize() else {
                continue;
            };
            if !real.starts_with(&self.root) {
                continue;
            }
            if real.is_dir() && depth < 3 && entry.path() == real {
                self.collect_documents(&real, depth + 1, names);
            } else if real.is_file() && is_document(&real) {
                names.push(self.name_of(&entry.path()));
            }
        }
    }
}

/// Whether `path` names a file the editor can open, by its extension.
fn is_document(path: &Path) -> bool {
    gradmesh::formats::Format::from_path(path).is_some() || gradmesh::formats::is_pdf_path(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hosts_and_origins() {
        let gate = Gate {
            token: "ab".into(),
            port: 8123,
        };
        assert!(gate.host_allowed("127.0.0.1:8123"));
        assert!(gate.host_allowed("localhost:8123"));
        assert!(!gate.host_allowed("127.0.0.1:8124"));
        assert!(!gate.host_allowed("evil.example:8123"));
        assert!(!gate.host_allowed("127.0.0.1"));
        assert!(gate.origin_allowed("http://127.0.0.1:8123"));
        assert!(!gate.origin_allowed("https://127.0.0.1:8123"));
        assert!(!gate.origin_allowed("http://evil.example:8123"));
        assert!(!gate.origin_allowed("null"));
        assert!(gate.token_matches("ab"));
        assert!(!gate.token_matches("aa"));
        assert!(!gate.token_matches("abc"));
    }

    #[test]
    fn tokens_differ() {
        let (a, b) = (new_token(), new_token());
        assert_eq!(a.len(), 32);
        assert_ne!(a, b);
    }

    #[test]
    fn names_stay_inside_the_folder() {
        let outside = tempfile::tempdir().unwrap();
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        std::fs::write(dir.path().join("a.json"), "{}").unwrap();
        std::fs::write(outside.path().join("secret.json"), "{}").unwrap();
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(
                outside.path().join("secret.json"),
                dir.path().join("l.json"),
            )
            .unwrap();
            std::os::unix::fs::symlink(outside.path(), dir.path().join("out")).unwrap();
        }
        let folder = Folder::new(dir.path()).unwrap();
        assert!(folder.resolve("a.json").is_ok());
        assert!(folder.resolve("sub/new.json").is_ok());
        assert!(folder.resolve("../x.json").is_err());
        assert!(folder.resolve("sub/../../x.json").is_err());
        assert!(folder.resolve("/etc/passwd").is_err());
        assert!(folder.resolve("").is_err());
        assert!(folder.resolve("missing/x.json").is_err());
        #[cfg(unix)]
        {
            assert!(folder.resolve("l.json").is_err());
            assert!(folder.resolve("out/secret.json").is_err());
            assert!(folder.resolve("out/new.json").is_err());
            assert_eq!(folder.documents(), vec!["a.json".to_string()]);
        }
    }
}
