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
        "--warnings",
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
        let scene = gradmesh::formats::svg::read_svg(&text).unwrap();
        let view = scene.view_rect();
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
        // The meshes alone (the command draws the rest of the picture too).
        let opts =
            gradmesh::render::RenderOptions::new(w, h, gradmesh::render::View::from_rect(view));
        let meshes = gradmesh::render::render_svg_scene(
            &scene,
            gradmesh::render::SvgMeshRendering::Scheme,
            &opts,
        )
        .unwrap()
        .0
        .to_u8(true);
        let uncovered = (0..pixels)
            .filter(|&i| alpha(&meshes, i) == 255 && alpha(&json_px, i) < 255)
            .count();
        assert_eq!(
            uncovered, 0,
            "{name}: the JSON leaves pixels of the SVG uncovered"
        );
    }
}

/// The CIEDE2000 difference of two sRGB colours (8-bit channels).
fn delta_e(a: &[u8], b: &[u8]) -> f64 {
    use gradmesh::ColourSpace;
    use palette::color_difference::Ciede2000;
    use palette::white_point::D65;
    use palette::Lab;
    let lab = |p: &[u8]| {
        let rgb = [p[0], p[1], p[2]].map(|c| f64::from(c) / 255.0);
        let c = ColourSpace::Srgb.convert(ColourSpace::Lab, rgb);
        Lab::<D65, f64>::new(c[0], c[1], c[2])
    };
    lab(a).difference(lab(b))
}

fn inkscape_render(name: &str) -> (u32, u32, Vec<u8>) {
    decode_png(
        &sample("../inkscape-1.2.2-renders")
            .join(name)
            .with_extension("png"),
    )
}

/// How the whole picture of `name` compares with Inkscape's render: the share of pixels
/// covered (alpha at least half) in both or neither, and the ΔE00 mean and largest share of
/// pixels far off over the pixels where Inkscape painted within ΔE00 `near` of `colour`
/// (content resvg draws: a flat fill, a stroke), at least `min_pixels` of them.
fn whole_picture_against_inkscape(
    name: &str,
    colour: [u8; 3],
    near: f64,
    min_pixels: usize,
) -> (f64, f64, usize) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("whole.png");
    let run = gradmesh(&[
        "render",
        sample(&format!("{name}.svg")).to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--warnings",
    ]);
    assert!(run.status.success(), "{run:?}");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!stderr.contains("left out: only"), "{name}: {stderr}");
    let (w, h, ours) = decode_png(&out);
    let (iw, ih, theirs) = inkscape_render(name);
    assert_eq!((w, h), (iw, ih), "{name}");
    let covered = |p: &[u8]| p[3] >= 128;
    let pixels = || ours.chunks_exact(4).zip(theirs.chunks_exact(4));
    let agree = pixels().filter(|(a, b)| covered(a) == covered(b)).count();
    let coverage = agree as f64 / (w * h) as f64;
    let flat: Vec<f64> = pixels()
        .filter(|(_, b)| b[3] == 255 && delta_e(b, &colour) < near)
        .map(|(a, b)| delta_e(a, b))
        .collect();
    let mean = flat.iter().sum::<f64>() / flat.len() as f64;
    eprintln!(
        "{name}: coverage agreement {:.4}, {} pixels near {colour:?}: ΔE00 mean {mean:.3}, {} above 5",
        coverage,
        flat.len(),
        flat.iter().filter(|d| **d > 5.0).count()
    );
    assert!(
        flat.len() >= min_pixels,
        "{name}: {} pixels near {colour:?}",
        flat.len()
    );
    (coverage, mean, flat.iter().filter(|d| **d > 5.0).count())
}

/// sample3: a flat ellipse beneath the meshes and a stroked path over its own mesh fill;
/// sample1: an ellipse over a mesh. Their whole pictures match Inkscape's renders.
#[test]
fn svg_whole_picture_matches_inkscape() {
    // sample3: the ellipse (#80ffb3) beneath, the black stroke of the mesh-filled path.
    let (coverage, mean, _) =
        whole_picture_against_inkscape("sample3", [0x80, 0xff, 0xb3], 1.0, 10_000);
    assert!(coverage > 0.99, "sample3 coverage {coverage}");
    assert!(mean < 1.0, "sample3 ellipse ΔE00 mean {mean}");
    let (_, mean, _) = whole_picture_against_inkscape("sample3", [0, 0, 0], 10.0, 30);
    assert!(mean < 5.0, "sample3 stroke ΔE00 mean {mean}");
    // sample1: the ellipse over the mesh.
    let (w, _, inkscape) = inkscape_render("sample1");
    let probe = 4 * (230 * w as usize + 230);
    let brown = [inkscape[probe], inkscape[probe + 1], inkscape[probe + 2]];
    let (coverage, mean, _) = whole_picture_against_inkscape("sample1", brown, 1.0, 10_000);
    assert!(coverage > 0.99, "sample1 coverage {coverage}");
    assert!(mean < 1.0, "sample1 ellipse ΔE00 mean {mean}");
}

const PAINT_ORDER: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100" viewBox="0 0 50 50">
  <defs><meshgradient id="blue" x="10" y="10" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
    <stop path="l 30,0" stop-color="#00f"/><stop path="l 0,30" stop-color="#00f"/>
    <stop path="l -30,0" stop-color="#00f"/><stop path="l 0,-30" stop-color="#00f"/>
  </meshpatch></meshrow></meshgradient></defs>
  <rect x="0" y="0" width="25" height="25" fill="#f00"/>
  <g><rect x="10" y="10" width="30" height="30" style="fill:url(#blue)" stroke="#000" stroke-width="2"/></g>
  <circle cx="40" cy="40" r="6" fill="#0f0"/>
</svg>"##;

/// A rect beneath a mesh fill, its stroke over it, and a circle above: each pixel shows the
/// topmost paint, at 8 and 16 bits and on a background.
#[test]
fn svg_whole_picture_keeps_paint_order() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("order.svg");
    std::fs::write(&input, PAINT_ORDER).unwrap();
    for (bits, background) in [("8", None), ("16", Some("#ffff00"))] {
        let out = dir.path().join(format!("order{bits}.png"));
        let mut args = vec![
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--bits",
            bits,
            "--warnings",
        ];
        if let Some(bg) = background {
            args.extend(["--background", bg]);
        }
        let run = gradmesh(&args);
        assert!(run.status.success(), "{run:?}");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!stderr.contains("left out"), "{stderr}");
        let (w, h, px) = decode_png(&out);
        assert_eq!((w, h), (100, 100));
        // Pixel coordinates are user units times 2.
        let at = |x: usize, y: usize| &px[4 * (y * 100 + x)..4 * (y * 100 + x) + 4];
        assert_eq!(at(10, 10), [255, 0, 0, 255], "the rect alone");
        assert_eq!(at(40, 40), [0, 0, 255, 255], "the mesh over the rect");
        assert_eq!(
            at(20, 50),
            [0, 0, 0, 255],
            "the mesh shape's stroke over its fill"
        );
        assert_eq!(at(80, 80), [0, 255, 0, 255], "the circle over the mesh");
        let empty = match background {
            Some(_) => [255, 255, 0, 255],
            None => [0, 0, 0, 0],
        };
        assert_eq!(at(90, 10), empty, "nothing painted");
    }
}

/// gradmesh's own SVG export read back: Paprika's three layers exported as thousands of
/// mesh-filled shapes (one patch each), with and without the PNG fallback beneath, render like
/// the PNG of the same layers: the same pixels covered, colours within a level or so, and no
/// fallback to drawing the meshes alone.
#[test]
fn exported_svg_reads_back_as_the_png_of_its_layers() {
    let dir = tempfile::tempdir().unwrap();
    let off = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/realdata/gradientmeshimproved-off"
    ));
    let layers: Vec<String> = (0..3)
        .map(|k| {
            let p = off.join(format!("Paprika_Paprika_layer{k}.off"));
            assert!(
                p.exists(),
                "{} is missing from ../shared/realdata",
                p.display()
            );
            p.to_str().unwrap().to_owned()
        })
        .collect();
    let png = dir.path().join("direct.png");
    let mut args: Vec<&str> = vec!["render"];
    args.extend(layers.iter().map(String::as_str));
    let render_to = |out: &std::path::Path, extra: &[&str]| {
        let mut a = args.clone();
        a.extend(["-o", out.to_str().unwrap(), "--width", "256"]);
        a.extend(extra);
        let o = gradmesh(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    render_to(&png, &[]);
    let (w, h, direct) = decode_png(&png);
    for extra in [&[][..], &["--no-fallback"][..]] {
        let svg = dir.path().join("exported.svg");
        render_to(&svg, extra);
        let text = std::fs::read_to_string(&svg).unwrap();
        let fills = text.matches("<meshgradient").count();
        assert!(fills > 1000, "{fills} mesh gradients");
        let back = dir.path().join("back.png");
        let o = gradmesh(&[
            "render",
            svg.to_str().unwrap(),
            "-o",
            back.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{stderr}");
        assert!(!stderr.contains("only the mesh fills"), "{stderr}");
        let (bw, bh, read_back) = decode_png(&back);
        assert_eq!((bw, bh), (w, h));
        let (mut both, mut differ, mut sum) = (0usize, 0usize, 0.0f64);
        for (a, b) in direct.chunks_exact(4).zip(read_back.chunks_exact(4)) {
            if (a[3] > 0) != (b[3] > 0) {
                differ += 1;
            }
            if a[3] == 255 && b[3] == 255 {
                both += 1;
                sum += (0..3)
                    .map(|c| (a[c] as f64 - b[c] as f64).abs())
                    .sum::<f64>()
                    / 3.0;
            }
        }
        let mean = sum / both as f64;
        assert!(both > 10_000, "{both} opaque pixels in both");
        assert!(differ * 100 < both, "{differ} pixels covered by one only");
        assert!(mean < 1.5, "mean difference {mean} levels ({extra:?})");
    }
}

/// A translucent layer (`examples/irregular-vertex.json` with corners 35 to 80 % opaque) over
/// an opaque one, exported as SVG with its PNG fallback and rendered back: the picture is the
/// direct render's. The masks the export writes are read into the layer's opacity, and the
/// PNG fallback stays hidden, as in any viewer that draws mesh gradients.
#[test]
fn exported_translucent_svg_reads_back_as_the_png() {
    let dir = tempfile::tempdir().unwrap();
    let examples = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples"));
    let mut star: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(examples.join("irregular-vertex.json")).unwrap(),
    )
    .unwrap();
    let points = star["layers"][0]["points"].as_array_mut().unwrap();
    for (i, p) in points.iter_mut().enumerate() {
        p["opacity"] = [0.35, 0.5, 0.65, 0.8, 0.45, 0.6][i % 6].into();
    }
    let star_path = dir.path().join("star.json");
    std::fs::write(&star_path, star.to_string()).unwrap();
    let rectangle = examples.join("rectangle.json");
    let run = |args: &[&str]| {
        let o = gradmesh(args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (png, svg, back) = (
        dir.path().join("direct.png"),
        dir.path().join("exported.svg"),
        dir.path().join("back.png"),
    );
    let inputs = [rectangle.to_str().unwrap(), star_path.to_str().unwrap()];
    for out in [&png, &svg] {
        let mut args = vec!["render"];
        args.extend(inputs);
        args.extend(["-o", out.to_str().unwrap(), "--width", "256"]);
        run(&args);
    }
    run(&[
        "render",
        svg.to_str().unwrap(),
        "-o",
        back.to_str().unwrap(),
    ]);
    let (w, h, direct) = decode_png(&png);
    let (bw, bh, read_back) = decode_png(&back);
    assert_eq!((bw, bh), (w, h));
    // Per pixel covered in either, the mean difference of the premultiplied channels (a
    // colour under little alpha weighs little), in levels.
    let pre = |p: &[u8], c: usize| p[c] as f64 * p[3] as f64 / 255.0;
    let mut differences: Vec<f64> = direct
        .chunks_exact(4)
        .zip(read_back.chunks_exact(4))
        .filter(|(a, b)| a[3] > 0 || b[3] > 0)
        .map(|(a, b)| {
            let colour: f64 = (0..3).map(|c| (pre(a, c) - pre(b, c)).abs()).sum();
            (colour + (a[3] as f64 - b[3] as f64).abs()) / 4.0
        })
        .collect();
    differences.sort_by(f64::total_cmp);
    let n = differences.len();
    let mean = differences.iter().sum::<f64>() / n as f64;
    let p95 = differences[n * 95 / 100];
    eprintln!("{n} pixels: mean difference {mean:.2} levels, 95th percentile {p95:.2}");
    // The outline differs by up to a pixel (the reader leaves out the layer's clip path, and
    // draws a mesh's edge without anti-aliasing), so the percentile is not the 99th. The PNG
    // fallback drawn beneath the meshes gives a mean of 3.7 and a 95th percentile of 33; the
    // layer read opaque, 18.5 and 64.
    assert!(n > 30_000, "{n} pixels covered");
    assert!(
        mean < 1.5 && p95 < 8.0,
        "mean {mean}, 95th percentile {p95} levels"
    );
}

/// A file whose mesh fills alternate with other content by the thousand: each part between
/// them would be a copy of the file for resvg to parse, so above the limit only the mesh fills
/// are drawn, with a warning that says why.
#[test]
fn too_many_parts_between_mesh_fills_draw_the_meshes_alone() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64" viewBox="0 0 64 64">"#,
    );
    for k in 0..3000 {
        let x = (k % 60) as f64;
        text.push_str(&format!(
            r##"<meshgradient id="m{k}" x="{x}" y="0"><meshrow><meshpatch><stop path="c 1,0 2,0 4,0" stop-color="#ff0000"/><stop path="c 0,1 0,2 0,4" stop-color="#00ff00"/><stop path="c -1,0 -2,0 -4,0" stop-color="#0000ff"/><stop path="c 0,-1 0,-2 0,-4" stop-color="#ffff00"/></meshpatch></meshrow></meshgradient><rect x="{x}" y="0" width="4" height="4" fill="url(#m{k})"/><rect x="{x}" y="10" width="4" height="4" fill="#000000"/>"##
        ));
    }
    text.push_str("</svg>");
    let svg = dir.path().join("many.svg");
    std::fs::write(&svg, &text).unwrap();
    let png = dir.path().join("many.png");
    let o = gradmesh(&["render", svg.to_str().unwrap(), "-o", png.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("only the mesh fills are drawn: 3000 parts of other content"),
        "{stderr}"
    );
    let (w, h, pixels) = decode_png(&png);
    assert_eq!((w, h), (64, 64));
    assert!(
        pixels.chunks_exact(4).any(|p| p[3] == 255),
        "the meshes are drawn"
    );
}

/// A file that uses the `<mesh>` element of Inkscape 0.92's pre-releases for its mesh
/// gradients (sample3 with its `meshGradient`s renamed) is drawn whole, as the same file with
/// `meshGradient`: the ellipse beneath and the stroke over the mesh-filled path are kept.
#[test]
fn the_draft_mesh_element_draws_the_rest_of_the_picture() {
    let source = std::fs::read_to_string(sample("sample3.svg")).unwrap();
    assert!(
        source.contains("<meshGradient"),
        "sample3 uses meshGradient"
    );
    let draft = source
        .replace("<meshGradient", "<mesh")
        .replace("</meshGradient>", "</mesh>");
    let dir = tempfile::tempdir().unwrap();
    let draft_svg = dir.path().join("draft.svg");
    std::fs::write(&draft_svg, draft).unwrap();
    let (draft_png, source_png) = (dir.path().join("draft.png"), dir.path().join("source.png"));
    for (svg, png) in [
        (draft_svg, &draft_png),
        (sample("sample3.svg"), &source_png),
    ] {
        let out = gradmesh(&["render", svg.to_str().unwrap(), "-o", png.to_str().unwrap()]);
        let message = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{message}");
        assert!(!message.contains("only the mesh fills"), "{message}");
    }
    let decode = |path: &std::path::Path| {
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut data = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut data).unwrap();
        data
    };
    let draft = decode(&draft_png);
    assert!(draft == decode(&source_png), "the draft's picture differs");
    // The ellipse (a flat fill drawn by resvg) is there: many opaque pixels of its #80ffb3.
    let ellipse = draft
        .chunks_exact(4)
        .filter(|p| p[..4] == [128, 255, 179, 255])
        .count();
    assert!(ellipse > 10_000, "{ellipse} pixels of the ellipse");
}

/// `convert --fit` writes the layers with their colours fitted to the file's classic painting,
/// with refined-level colour edits; a file without classic meshes is refused, nothing written.
#[test]
fn convert_fit_fits_the_colours_and_refuses_other_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let svg = sample("sample6.svg");
    let (plain, fitted) = (
        dir.path().join("plain.json"),
        dir.path().join("fitted.json"),
    );
    for (json, fit) in [(&plain, false), (&fitted, true)] {
        let mut args = vec![
            "convert",
            svg.to_str().unwrap(),
            "-o",
            json.to_str().unwrap(),
        ];
        if fit {
            args.push("--fit");
        }
        let out = gradmesh(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let (plain, fitted_text) = (
        std::fs::read_to_string(&plain).unwrap(),
        std::fs::read_to_string(&fitted).unwrap(),
    );
    assert!(!plain.contains("\"edits\""), "{plain}");
    assert!(fitted_text.contains("\"edits\""), "no edits written");
    let again = dir.path().join("again.json");
    let out = gradmesh(&[
        "convert",
        fitted.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
        "--fit",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("--fit needs an SVG or PDF input"),
        "{stderr}"
    );
    assert!(!again.exists());
}
