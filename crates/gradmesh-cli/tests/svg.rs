//! `gradmesh convert` and `gradmesh render` on an SVG file with mesh gradients, for real in a
//! temporary directory: the warnings name what was left out, and the round trip SVG -> JSON ->
//! PNG works.

use std::path::PathBuf;
use std::process::{Command, Output};

fn sample(name: &str) -> PathBuf {
    let path = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/realdata/meshgradient/zectorio-mesh-gradient-js"
    ))
    .join(name);
    assert!(
        path.exists(),
        "{} is missing from ../shared/realdata",
        path.display()
    );
    path
}

fn gradmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gradmesh"))
        .args(args)
        .output()
        .expect("the binary runs")
}

#[test]
fn svg_converts_to_json_and_renders() {
    let dir = tempfile::tempdir().unwrap();
    let svg = sample("sample3.svg");
    let json = dir.path().join("sample3.json");
    let out = gradmesh(&[
        "convert",
        svg.to_str().unwrap(),
        "-o",
        json.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(r##"<ellipse id="ellipse5941"> at 254:3: fill "#80ffb3" left out"##),
        "{stderr}"
    );
    let text = std::fs::read_to_string(&json).unwrap();
    assert_eq!(
        text.matches("\"name\": \"meshGradient").count(),
        3,
        "{text}"
    );
    for input in [svg.as_path(), json.as_path()] {
        let png = dir.path().join("out.png");
        let out = gradmesh(&[
            "render",
            input.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--width",
            "120",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::metadata(&png).unwrap().len() > 100);
    }
}
