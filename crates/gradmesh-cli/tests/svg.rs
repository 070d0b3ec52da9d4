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

/// The RGBA8 pixels of a PNG file, with its size.
fn decode_png(path: &std::path::Path) -> (u32, u32, Vec<u8>) {
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

/// Without `--view` and a size, an SVG file renders its own viewport at its own size: the
/// picture has the size of Inkscape's render of the same file, and where the file holds
/// nothing but unclipped mesh fills (the W3C square and star), it covers the same pixels.
#[test]
fn svg_renders_its_own_viewport_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let renders = sample("sample3.svg")
        .parent()
        .unwrap()
        .join("../inkscape-1.2.2-renders");
    for (svg, same_coverage) in [
        (sample("sample5.svg"), false),
        (sample("../wpt/meshgradient-basic-001.svg"), true),
        (sample("../wpt/meshgradient-basic-005.svg"), true),
    ] {
        let name = svg.file_stem().unwrap().to_str().unwrap().to_string();
        let png = dir.path().join(format!("{name}.png"));
        let out = gradmesh(&["render", svg.to_str().unwrap(), "-o", png.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (w, h, ours) = decode_png(&png);
        let (iw, ih, inkscape) = decode_png(&renders.join(format!("{name}.png")));
        assert_eq!((w, h), (iw, ih), "{name}: size");
        if !same_coverage {
            continue;
        }
        let covered = |data: &[u8], i: usize| data[4 * i + 3] > 127;
        let pixels = (w * h) as usize;
        let disagree = (0..pixels)
            .filter(|&i| covered(&ours, i) != covered(&inkscape, i))
            .count();
        let inside = (0..pixels).filter(|&i| covered(&inkscape, i)).count();
        assert!(
            inside > pixels / 20,
            "{name}: Inkscape covers {inside} pixels"
        );
        assert!(
            disagree * 100 < inside,
            "{name}: {disagree} of {pixels} pixels differ in coverage from Inkscape's render"
        );
    }
}

/// The 13 test files: the W3C tests and the Inkscape samples.
fn all_test_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = (1..=5)
        .map(|k| sample(&format!("../wpt/meshgradient-basic-00{k}.svg")))
        .collect();
    files.push(sample("../wpt/meshgradient-bicubic-001.svg"));
    files.push(sample("../wpt/meshgradient-complex-001.svg"));
    files.extend((1..=6).map(|k| sample(&format!("sample{k}.svg"))));
    files
}

/// Every test file goes SVG -> `convert` -> JSON -> `render`, and renders straight from the
/// SVG with `--svg-mesh classic` and `scheme`: the three pictures have the file's size; the
/// classic and the scheme render, both clipped to the shapes, cover the same pixels (to the
/// outlines' anti-aliasing), except in the W3C file whose patches fold beyond the mesh's
/// outline (the classic painting covers every patch, the scheme its outline's inside); and
/// the JSON's layers, which are not clipped, cover every pixel the clipped scheme render
/// covers.
#[test]
fn every_test_file_round_trips_through_json_and_renders_both_ways() {
    let dir = tempfile::tempdir().unwrap();
    for svg in all_test_files() {
        let name = svg.file_stem().unwrap().to_str().unwrap().to_string();
        let json = dir.path().join(format!("{name}.json"));
        let run = |args: &[&str]| {
            let out = gradmesh(args);
            assert!(
                out.status.success(),
                "{name}: {args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        };
        let (svg_arg, json_arg) = (svg.to_str().unwrap(), json.to_str().unwrap());
        run(&["convert", svg_arg, "-o", json_arg]);
        let png = |what: &str| dir.path().join(format!("{name}-{what}.png"));
        let (from_json, classic, scheme) = (png("json"), png("classic"), png("scheme"));
        let (w, h, _) = decode_png(
            &sample("sample3.svg")
                .parent()
                .unwrap()
                .join(format!("../inkscape-1.2.2-renders/{name}.png")),
        );
        // The JSON keeps the root's user units: drawn with the SVG's view box.
        let text = std::fs::read_to_string(&svg).unwrap();
        let view = gradmesh::formats::svg::read_svg(&text)
            .unwrap()
            .view_rect()
            .unwrap();
        let numbers = [w, h]
            .map(|v| v.to_string())
            .into_iter()
            .chain([view.x0, view.y0, view.x1, view.y1].map(|v| v.to_string()))
            .collect::<Vec<_>>();
        let mut args = vec!["render", json_arg, "-o", from_json.to_str().unwrap()];
        args.extend(["--width", &numbers[0], "--height", &numbers[1], "--view"]);
        args.extend(numbers[2..].iter().map(String::as_str));
        run(&args);
        for (mode, out) in [("classic", &classic), ("scheme", &scheme)] {
            run(&[
                "render",
                svg_arg,
                "-o",
                out.to_str().unwrap(),
                "--svg-mesh",
                mode,
            ]);
        }
        let [json_px, classic_px, scheme_px] = [&from_json, &classic, &scheme].map(|p| {
            let (pw, ph, data) = decode_png(p);
            assert_eq!((pw, ph), (w, h), "{name}: {}", p.display());
            data
        });
        let alpha = |data: &[u8], i: usize| data[4 * i + 3];
        let pixels = (w * h) as usize;
        let covered = (0..pixels).filter(|&i| alpha(&classic_px, i) > 127).count();
        assert!(
            covered > pixels / 50,
            "{name}: classic covers {covered} pixels"
        );
        let disagree = (0..pixels)
            .filter(|&i| (alpha(&classic_px, i) > 127) != (alpha(&scheme_px, i) > 127))
            .count();
        assert!(
            disagree * 50 < covered || name == "meshgradient-complex-001",
            "{name}: classic and scheme coverage differ on {disagree} of {covered} pixels"
        );
        let uncovered = (0..pixels)
            .filter(|&i| alpha(&scheme_px, i) == 255 && alpha(&json_px, i) < 255)
            .count();
        assert_eq!(
            uncovered, 0,
            "{name}: the JSON leaves pixels of the SVG uncovered"
        );
    }
}
