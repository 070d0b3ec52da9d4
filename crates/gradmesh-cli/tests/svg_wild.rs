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

/// 98 Mpx of whole picture is under the pixel limit but needs more memory than 500 MB (8 bytes
/// a pixel: 784 MB): refused before anything is allocated, with the estimate and the flag to
/// raise it.
#[test]
fn a_whole_picture_over_the_memory_limit_is_refused() {
    let (out, dir) = render(
        "F8-pdf-page-size-inkscape-ext-mesh.svg",
        &["--width", "7200", "--max-memory", "500000000"],
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
        &["--width", "720", "--max-memory", "500000000"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

/// The mesh fill's tessellation counts against `--max-memory`, before it is made: F8 at 2000 px
/// needs 60 MB for its canvas and PNG, and about 150 MB more for the cells of its mesh fill.
#[test]
fn the_mesh_fills_cells_count_against_the_memory_limit() {
    let (out, dir) = render(
        "F8-pdf-page-size-inkscape-ext-mesh.svg",
        &["--width", "2000", "--max-memory", "100000000"],
    );
    let message = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{message}");
    assert!(message.contains("mesh fills' cells"), "{message}");
    assert!(!dir.path().join("out.png").exists());
    let (out, _dir) = render(
        "F8-pdf-page-size-inkscape-ext-mesh.svg",
        &["--width", "2000", "--max-memory", "300000000"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

/// The bounding box (x0, y0, x1, y1) of the pixels where `is` holds.
fn bounds(png: &Path, is: impl Fn(&[u8]) -> bool) -> Option<(u32, u32, u32, u32)> {
    let (w, _, data) = decode_png(png);
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for (i, p) in data.chunks_exact(4).enumerate() {
        if is(p) {
            let (x, y) = (i as u32 % w, i as u32 / w);
            b = Some(match b {
                None => (x, y, x, y),
                Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
            });
        }
    }
    b
}

/// A 200 x 100 viewport over a 200 x 200 view box (`xMidYMid meet`, the initial value): the
/// view box is drawn at half size in the middle, so the red square stays square.
#[test]
fn preserve_aspect_ratio_keeps_squares_square() {
    let (out, dir) = render("F7-preserveAspectRatio-ignored.svg", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let png = dir.path().join("out.png");
    let (w, h, _) = decode_png(&png);
    assert_eq!((w, h), (200, 100));
    let red = |p: &[u8]| p[0] > 200 && p[1] < 60 && p[2] < 60 && p[3] > 200;
    // The square of side 110 (stroke 4) at (45, 45): x 71.5-128.5, y 21.5-78.5 in pixels.
    let (x0, y0, x1, y1) = bounds(&png, red).expect("the red square is drawn");
    assert!((x1 - x0).abs_diff(y1 - y0) <= 1, "{:?}", (x0, y0, x1, y1));
    assert!(
        (71..=73).contains(&x0) && (21..=23).contains(&y0),
        "{:?}",
        (x0, y0)
    );
    // Left of the view box (x < 50 px) nothing is drawn.
    assert_eq!(bounds(&png, |p| p[3] > 0).map(|b| b.0), Some(50));
}

/// A relative `<image href>` is found beside the SVG file wherever the command runs; when it
/// is missing, a warning names it.
#[test]
fn relative_images_are_found_beside_the_file() {
    let (out, dir) = render("F9-external-image-dropped.svg", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("image"), "{}", stderr(&out));
    let png = dir.path().join("out.png");
    // The image covers x 110-190, y 10-90.
    let drawn = bounds(&png, |p| p[3] > 127).expect("something is drawn");
    assert!(drawn.2 >= 185, "{drawn:?}");

    let alone = tempfile::tempdir().unwrap();
    let svg = alone.path().join("F9.svg");
    std::fs::copy(wild("F9-external-image-dropped.svg"), &svg).unwrap();
    let out = gradmesh_in(
        dir.path(),
        &["render", svg.to_str().unwrap(), "-o", "alone.png"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(
        message.contains("<image> at 3:3: href \"image.png\"") && message.contains("missing"),
        "{message}"
    );
}

/// `width="0" height="0"` and no view box: CSS's default size, 300 x 150, showing the green
/// rect beneath the mesh.
#[test]
fn a_zero_size_is_the_css_default() {
    let (out, dir) = render("F10-zero-size-view-is-mesh-bounds.svg", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let png = dir.path().join("out.png");
    let (w, h, data) = decode_png(&png);
    assert_eq!((w, h), (300, 150));
    let pixel = |x: u32, y: u32| &data[4 * (y * w + x) as usize..][..4];
    assert_eq!(pixel(150, 120)[3], 255);
    assert!(
        pixel(150, 120)[1] > 100 && pixel(150, 120)[0] < 30,
        "{:?}",
        pixel(150, 120)
    );
    assert_eq!(pixel(250, 50)[3], 0);
}

/// An invalid attribute on another element is ignored with a warning naming the element, the
/// attribute and the line (counted in one line by default, listed with `--warnings`); the rest
/// of the picture is drawn.
#[test]
fn invalid_attributes_are_ignored_with_a_warning() {
    for (name, attribute) in [
        ("F11-invalid-opacity-rejects-file.svg", "opacity \"1x\""),
        (
            "F11b-invalid-transform-rejects-file.svg",
            "transform \"qwe\"",
        ),
    ] {
        let (quiet, _) = render(name, &[]);
        let summary = stderr(&quiet);
        assert!(
            summary.contains("1 SVG attribute ignored or read differently: --warnings to list")
                && summary.lines().count() == 1,
            "{name}: {summary}"
        );
        let (out, dir) = render(name, &["--warnings"]);
        let message = stderr(&out);
        assert!(out.status.success(), "{name}: {message}");
        assert!(
            message.contains(&format!("<rect> at 3:3: {attribute}")) && message.contains("ignored"),
            "{name}: {message}"
        );
        // The black square at x 110-190 is drawn, as resvg draws it.
        let (w, _, data) = decode_png(&dir.path().join("out.png"));
        let p = &data[4 * (50 * w + 150) as usize..][..4];
        assert_eq!(p, [0, 0, 0, 255], "{name}");
    }
}

/// PDF pages are in points at 96 CSS pixels to 72 points, as Inkscape makes them: the
/// 129.47 mm x 244.54 mm drawing is a 367 x 693.17 pt page (Inkscape 1.2.2's MediaBox).
#[test]
fn pdf_pages_have_inkscapes_size() {
    let dir = tempfile::tempdir().unwrap();
    let svg = wild("F8-pdf-page-size-inkscape-ext-mesh.svg");
    let out = gradmesh_in(
        dir.path(),
        &["render", svg.to_str().unwrap(), "-o", "out.pdf"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let pdf = std::fs::read(dir.path().join("out.pdf")).unwrap();
    let text = String::from_utf8_lossy(&pdf);
    let at = text.find("/MediaBox [").expect("a MediaBox");
    let numbers: Vec<f64> = text[at + 11..]
        .split(']')
        .next()
        .unwrap()
        .split_whitespace()
        .map(|n| n.parse().unwrap())
        .collect();
    assert_eq!(numbers.len(), 4, "{numbers:?}");
    assert!((numbers[2] - 367.0).abs() < 0.01, "{numbers:?}");
    assert!((numbers[3] - 693.174).abs() < 0.01, "{numbers:?}");
}

/// The mesh fill `scripts/resvg-suite.sh` adds to every file: a 1x1 patch far off the canvas.
const PROBE: &str = concat!(
    "<defs><meshgradient id=\"gm_probe_mesh\" x=\"-100000\" y=\"-100000\" ",
    "gradientUnits=\"userSpaceOnUse\"><meshrow><meshpatch>",
    "<stop path=\"l 1,0\" stop-color=\"#f00\"/><stop path=\"l 0,1\" stop-color=\"#f00\"/>",
    "<stop path=\"l -1,0\" stop-color=\"#f00\"/><stop path=\"l 0,-1\" stop-color=\"#f00\"/>",
    "</meshpatch></meshrow></meshgradient></defs>",
    "<rect x=\"-100000\" y=\"-100000\" width=\"1\" height=\"1\" fill=\"url(#gm_probe_mesh)\"/>"
);

/// How many pixels differ by more than one level in a channel (resvg's suite's test), leaving
/// out pixels clear in both.
fn pixels_off_reference(actual: &[u8], reference: &Path) -> usize {
    let (_, _, expected) = decode_png(reference);
    assert_eq!(actual.len(), expected.len(), "{}", reference.display());
    actual
        .chunks_exact(4)
        .zip(expected.chunks_exact(4))
        .filter(|(p, q)| !(p[3] == 0 && q[3] == 0) && (0..4).any(|c| p[c].abs_diff(q[c]) > 1))
        .count()
}

/// Six tests of resvg's own suite (`tests/data/resvg-suite/`, its README says which), with a
/// mesh fill added off the canvas, are drawn through the whole-picture path as resvg's
/// reference PNGs show them: every pixel within one level.
#[test]
fn resvg_suite_samples_match_their_references() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/resvg-suite");
    let mut names: Vec<PathBuf> = std::fs::read_dir(&data)
        .unwrap_or_else(|e| panic!("{}: {e}", data.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    names.sort();
    assert_eq!(names.len(), 6, "the six SVG files of {}", data.display());
    let dir = tempfile::tempdir().unwrap();
    for svg in &names {
        let text = std::fs::read_to_string(svg).unwrap();
        let close = text.rfind("</svg>").expect("a closing </svg>");
        let injected = format!("{}{PROBE}{}", &text[..close], &text[close..]);
        let input = dir.path().join("in.svg");
        std::fs::write(&input, injected).unwrap();
        let reference = svg.with_extension("png");
        let (w, h, _) = decode_png(&reference);
        let (w, h) = (w.to_string(), h.to_string());
        let args = [
            "render",
            "in.svg",
            "-o",
            "out.png",
            "--force",
            "--width",
            &w,
            "--height",
            &h,
            "--no-dither",
        ];
        let out = gradmesh_in(dir.path(), &args);
        let name = svg.file_name().unwrap().to_string_lossy();
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert!(
            !stderr(&out).contains("only the mesh fills"),
            "{name}: {}",
            stderr(&out)
        );
        let (_, _, actual) = decode_png(&dir.path().join("out.png"));
        let off = pixels_off_reference(&actual, &reference);
        assert_eq!(off, 0, "{name}: {off} pixels differ from resvg's reference");
    }
}

/// The whole picture is drawn into one canvas, not copies: F8 at 7200 px wide (98 Mpx, a mesh
/// over most of the page beneath resvg's content) peaks at 7.4 bytes a pixel (4 of them the
/// canvas; the mesh's tessellation is bounded by `--max-quads`), where an `f32` canvas, an
/// `f32` mesh layer and a segment took over 40. Peak resident memory from `/usr/bin/time`.
#[test]
fn a_whole_picture_costs_a_few_bytes_a_pixel() {
    let time = Path::new("/usr/bin/time");
    assert!(time.exists(), "{} (GNU time) is missing", time.display());
    let dir = tempfile::tempdir().unwrap();
    let svg = wild("F8-pdf-page-size-inkscape-ext-mesh.svg");
    let out = Command::new(time)
        .current_dir(dir.path())
        .args([
            "-f",
            "peak-kib %M",
            env!("CARGO_BIN_EXE_gradmesh"),
            "render",
        ])
        .arg(&svg)
        .args(["-o", "out.png", "--width", "7200"])
        .output()
        .expect("/usr/bin/time runs");
    let message = stderr(&out);
    assert!(out.status.success(), "{message}");
    // The size from the PNG's header (IHDR's width and height follow the 16-byte start).
    let png = std::fs::read(dir.path().join("out.png")).unwrap();
    let be = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
    let (w, h) = (be(16), be(20));
    assert_eq!((w, h), (7200, 13599));
    let kib: f64 = message
        .lines()
        .find_map(|l| l.strip_prefix("peak-kib "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or_else(|| panic!("no peak in {message:?}"));
    let per_pixel = kib * 1024.0 / (f64::from(w) * f64::from(h));
    assert!(per_pixel < 10.0, "{per_pixel:.1} bytes a pixel at {w}x{h}");
}
