//! `gradmesh render -o OUT.pdf`: the binary run for real in temporary directories.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn gradmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gradmesh"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The width and height in a PNG's header.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    let be = |k: usize| u32::from_be_bytes(bytes[k..k + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn a_pdf_is_written_with_the_png_page_size() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("irregular-vertex.json");
    let (pdf, png) = (dir.path().join("out.pdf"), dir.path().join("out.png"));
    let o = gradmesh(&["render", s(&input), "-o", s(&pdf), "--width", "160"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&pdf).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(bytes.starts_with(b"%PDF-"));
    assert!(
        text.contains("/ShadingType 7") && text.contains("/DeviceRGB"),
        "{text:.400}"
    );
    let o = gradmesh(&["render", s(&input), "-o", s(&png), "--width", "160"]);
    assert!(o.status.success(), "{}", stderr(&o));

    // A 96-dpi rasterisation has the PNG's size.
    let drawn = dir.path().join("drawn.png");
    let o = Command::new("mutool")
        .args(["draw", "-q", "-r", "96", "-o", s(&drawn), s(&pdf), "1"])
        .output()
        .unwrap_or_else(|e| panic!("mutool could not be run ({e}): apt-get install mupdf-tools"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(png_size(&drawn), png_size(&png));
}

#[test]
fn pdf_colour_and_tolerance_flags() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("irregular-vertex.json");
    let size = |args: &[&str]| -> (String, usize) {
        let out = dir.path().join("flags.pdf");
        let o = gradmesh(
            &[
                &["render", s(&input), "-o", s(&out), "--width", "128"],
                args,
            ]
            .concat(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let bytes = std::fs::read(&out).unwrap();
        (String::from_utf8_lossy(&bytes).into_owned(), bytes.len())
    };
    let (default, _) = size(&[]);
    assert!(default.contains("/DeviceRGB") && !default.contains("/Lab"));
    let (lab, _) = size(&["--pdf-colour", "lab"]);
    assert!(lab.contains("/Lab"));
    let (_, coarse) = size(&["--tolerance", "2"]);
    let (_, fine) = size(&["--tolerance", "0.2"]);
    assert!(fine > 2 * coarse, "{fine} vs {coarse}");
}

#[test]
fn png_only_flags_are_named_in_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("irregular-vertex.json");
    let out = dir.path().join("flags.svg");
    let o = gradmesh(&[
        "render",
        s(&input),
        "-o",
        s(&out),
        "--width",
        "64",
        "--bits",
        "16",
        "--boundary",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--bits, --boundary only apply to PNG output"),
        "{}",
        stderr(&o)
    );
    let o = gradmesh(&["render", s(&input), "-o", s(&out), "--width", "64"]);
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

#[test]
fn bad_vector_options_are_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("irregular-vertex.json");
    let out = dir.path().join("bad.pdf");
    let o = gradmesh(&["render", s(&input), "-o", s(&out), "--tolerance", "0"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("export tolerance"), "{}", stderr(&o));
    assert!(!out.exists());
    let o = gradmesh(&["render", s(&input), "-o", s(&out), "--pdf-colour", "cmyk"]);
    assert!(!o.status.success());
    let tiff = dir.path().join("out.tiff");
    let o = gradmesh(&["render", s(&input), "-o", s(&tiff)]);
    assert!(stderr(&o).contains("render writes .png"), "{}", stderr(&o));
}

#[test]
fn an_svg_is_written_with_mesh_gradients_and_a_fallback() {
    let dir = tempfile::tempdir().unwrap();
    let input = example("irregular-vertex.json");
    let out = dir.path().join("out.svg");
    let o = gradmesh(&["render", s(&input), "-o", s(&out), "--width", "96"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("<meshgradient") && text.contains("data:image/png;base64,"));
    let o = gradmesh(&[
        "render",
        s(&input),
        "-o",
        s(&out),
        "--width",
        "96",
        "--no-fallback",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!std::fs::read_to_string(&out).unwrap().contains("<image"));
}
