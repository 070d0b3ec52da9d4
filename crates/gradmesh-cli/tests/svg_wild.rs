//! `gradmesh render` on SVG files from other projects' test suites that once crashed it, took
//! too long or drew the wrong picture (`../shared/realdata/svg-wild/`, its README says where
//! each comes from): each with the behaviour it should have.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn wild(name: &str) -> PathBuf {
    let path = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/realdata/svg-wild"
    ))
    .join(name);
    assert!(
        path.exists(),
        "{} is missing from ../shared/realdata",
        path.display()
    );
    path
}

fn gradmesh_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gradmesh"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Renders `name` to a PNG in a temporary folder with `extra` flags.
fn render(name: &str, extra: &[&str]) -> (Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let svg = wild(name);
    let mut args = vec!["render", svg.to_str().unwrap(), "-o", "out.png"];
    args.extend_from_slice(extra);
    (gradmesh_in(dir.path(), &args), dir)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The RGBA8 pixels of a PNG file, with its size.
fn decode_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().unwrap();
    let mut data = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut data).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgba, "{}", path.display());
    data.truncate(info.buffer_size());
    (info.width, info.height, data)
}

/// The share of the picture's pixels that are at least half opaque.
fn covered_share(png: &Path) -> f64 {
    let (w, h, data) = decode_png(png);
    let covered = data.chunks_exact(4).filter(|p| p[3] > 127).count();
    covered as f64 / f64::from(w * h)
}

/// Files that panicked inside resvg/usvg 0.45 (filters, text layout) draw their whole picture.
#[test]
fn files_that_panicked_inside_resvg_draw() {
    for (name, size) in [
        ("F1a-panic-composite-resvg-arithmetic-huge-region.svg", None),
        ("F1b-panic-composite-jsvg-composite.svg", None),
        ("F1c-panic-composite-svgwg-feComposite.svg", None),
        ("F2-panic-displacement-jsvg-negative-coords.svg", None),
        (
            "F3a-panic-text-layout923-resvg-glyph-splitting.svg",
            Some("300"),
        ),
        (
            "F3b-panic-text-layout923-inkscape-text-glyphs-vertical.svg",
            Some("300"),
        ),
        (
            "F3c-panic-text-layout1422-resvg-arabic-script.svg",
            Some("300"),
        ),
    ] {
        let extra: Vec<&str> = match size {
            Some(s) => vec!["--width", s, "--height", s],
            None => vec![],
        };
        let (out, dir) = render(name, &extra);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert!(
            !stderr(&out).contains("only the mesh fills are drawn"),
            "{name}: {}",
            stderr(&out)
        );
        // Every one of them draws a frame, a flat fill or text across the canvas; the mesh
        // fill is 1 px far outside it.
        let share = covered_share(&dir.path().join("out.png"));
        assert!(share > 0.001, "{name}: {share} of the pixels covered");
    }
}

/// A filter region of 35,200 x 37,800 pixels (5.3 GB) is clipped as resvg clips layers, and
/// the whole picture is drawn within 4 GB of address space; a layer over `--max-pixels` is
/// refused, naming the filter.
#[test]
fn a_huge_filter_region_is_bounded() {
    let name = "F4-abort-5GB-alloc-jsvg-blend_bug41.svg";
    let dir = tempfile::tempdir().unwrap();
    let svg = wild(name);
    let script = format!(
        "ulimit -v 4000000 && exec '{}' render '{}' -o out.png",
        env!("CARGO_BIN_EXE_gradmesh"),
        svg.display()
    );
    let out = Command::new("sh")
        .current_dir(dir.path())
        .args(["-c", &script])
        .output()
        .expect("sh runs");
    assert!(out.status.success(), "{}", stderr(&out));
    // The black square, x 10-30 and y 5-26 of a 18 x 14 view box at 40 px a unit.
    let (w, _, data) = decode_png(&dir.path().join("out.png"));
    let pixel = |x: u32, y: u32| &data[4 * (y * w + x) as usize..][..4];
    let dark_and_opaque = |p: &[u8]| p[..3].iter().all(|&c| c < 10) && p[3] == 255;
    assert!(dark_and_opaque(pixel(600, 400)), "{:?}", pixel(600, 400));
    assert!(!dark_and_opaque(pixel(200, 100)), "{:?}", pixel(200, 100));

    let (out, _dir) = render(name, &["--max-pixels", "2000000"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(
        message.contains("filter id=\"b\"") && message.contains("--max-pixels"),
        "{message}"
    );
    assert!(!message.contains("panicked"), "{message}");
}

/// feMorphology with a radius of 9,999 would read ~2.8e10 pixels: refused at once, naming it.
#[test]
fn a_morphology_filter_with_a_huge_radius_is_refused() {
    let started = std::time::Instant::now();
    let (out, _dir) = render(
        "F6-slow-feMorphology-huge-radius.svg",
        &["--width", "300", "--height", "300"],
    );
    let message = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{message}");
    assert!(
        message.contains("feMorphology") && message.contains("filter id=\"filter1\""),
        "{message}"
    );
    // The check runs before resvg draws (7-10 s); generous for a loaded machine.
    assert!(started.elapsed().as_secs() < 5, "{:?}", started.elapsed());
}

/// 98 Mpx of whole picture is under the pixel limit but needs more memory than 4 GB: refused
/// before anything is allocated, with the estimate and the flag to raise it.
#[test]
fn a_whole_picture_over_the_memory_limit_is_refused() {
    let (out, dir) = render(
        "F8-pdf-page-size-inkscape-ext-mesh.svg",
        &["--width", "7200", "--max-memory", "4000000000"],
    );
    let message = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{message}");
    assert!(
        message.contains("F8-pdf-page-size")
            && message.contains("memory")
            && message.contains("--max-memory"),
        "{message}"
    );
    assert!(!dir.path().join("out.png").exists());
    // The same picture at 720 px is drawn.
    let (out, _dir) = render(
        "F8-pdf-page-size-inkscape-ext-mesh.svg",
        &["--width", "720", "--max-memory", "4000000000"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}
