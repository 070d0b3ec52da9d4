//! `gradmesh vectorise`: a photograph to a mesh that `gradmesh render` draws at the photograph's
//! size, and clear errors on files that are not pictures.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn gradmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gradmesh"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn photo(name: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/realdata/images")
        .join(name);
    assert!(
        path.exists(),
        "{} is missing: the tests need ../shared/realdata beside the repository",
        path.display()
    );
    path
}

/// The JSON written renders, by default, to a picture of the photograph's size close to it.
#[test]
fn vectorise_then_render_gives_the_pictures_size() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("chelsea.json");
    let png = dir.path().join("chelsea.png");
    let input = photo("chelsea.png");
    let out = gradmesh(&["vectorise", s(&input), "-o", s(&json), "--points", "200"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("PSNR"), "{stderr}");
    let out = gradmesh(&["render", s(&json), "-o", s(&png)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let info = decoder.read_info().unwrap();
    assert_eq!(info.info().size(), (451, 300));
    let doc = gradmesh::formats::read_path(&json).unwrap();
    assert_eq!(doc.layers.len(), 1);
    assert!(doc.layers[0].points.len() <= 200);
}

/// A file that is not a picture, a picture beyond the pixel limit, and an output that is not
/// JSON are refused with the file named; nothing is written.
#[test]
fn bad_inputs_are_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("out.json");
    let text = dir.path().join("not-a-picture.png");
    std::fs::write(&text, "hello").unwrap();
    let out = gradmesh(&["vectorise", s(&text), "-o", s(&json)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("not-a-picture.png") && stderr.contains("not a PNG or JPEG"),
        "{stderr}"
    );
    let input = photo("coffee.png");
    let out = gradmesh(&[
        "vectorise",
        s(&input),
        "-o",
        s(&json),
        "--max-pixels",
        "1000",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("above the limit"), "{stderr}");
    let out = gradmesh(&["vectorise", s(&input), "-o", s(&dir.path().join("out.png"))]);
    assert!(!out.status.success());
    assert!(!json.exists());
}
