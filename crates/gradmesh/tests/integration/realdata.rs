//! The real data the tests read from `../shared/realdata/` beside the repository (see the
//! README, Test data): the paper authors' artwork and the outputs of their implementation.
//! A test that needs it fails, naming the path it expected, when it is missing; none skips.

use std::path::{Path, PathBuf};

/// `../shared/realdata/gradientmeshimproved-off`, beside the repository.
pub fn dir() -> PathBuf {
    // CARGO_MANIFEST_DIR is `<repository>/crates/gradmesh`.
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = crate_dir.join("../../../shared/realdata/gradientmeshimproved-off");
    require(dir, "../shared/realdata is missing")
}

/// The file (or folder) `name` of [`dir`], e.g. `"Glasses.off"` or `"reference-output"`.
pub fn path(name: &str) -> PathBuf {
    require(
        dir().join(name),
        &format!("{name} is missing from ../shared/realdata"),
    )
}

/// The file (or folder) `name` of `../shared/realdata/meshgradient` beside the repository, e.g.
/// `"wpt/meshgradient-basic-001.svg"`.
pub fn meshgradient(name: &str) -> PathBuf {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = crate_dir
        .join("../../../shared/realdata/meshgradient")
        .join(name);
    require(
        path,
        &format!("meshgradient/{name} is missing from ../shared/realdata"),
    )
}

/// The photograph `name` of `../shared/realdata/images` beside the repository, e.g.
/// `"coffee.png"`.
pub fn image(name: &str) -> PathBuf {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = crate_dir.join("../../../shared/realdata/images").join(name);
    require(
        path,
        &format!("images/{name} is missing from ../shared/realdata"),
    )
}

/// `path`; panics with `what` and the path when it does not exist.
fn require(path: PathBuf, what: &str) -> PathBuf {
    assert!(
        path.exists(),
        "{what}: expected {}; tests need it beside the repository (see README, Test data)",
        absolute(&path).display()
    );
    path
}

/// `path` without `..` components, for the message (the path need not exist).
fn absolute(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}
