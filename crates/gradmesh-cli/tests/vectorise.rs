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

/// A picture with a transparent background: the mesh covers the opaque disc alone, and the
/// document's view keeps the picture's rectangle, so `gradmesh render` draws the picture's
/// size by default, transparent where the picture is.
#[test]
fn a_transparent_picture_renders_at_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let (input, json, out_png) = (
        dir.path().join("disc.png"),
        dir.path().join("disc.json"),
        dir.path().join("back.png"),
    );
    let (w, h) = (90u32, 60u32);
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (dx, dy) = (x as f64 + 0.5 - 50.0, y as f64 + 0.5 - 30.0);
            let inside = dx * dx + dy * dy < 22.0 * 22.0;
            data.extend([200, (x * 2) as u8, 80, if inside { 255 } else { 0 }]);
        }
    }
    let mut encoder = png::Encoder::new(std::fs::File::create(&input).unwrap(), w, h);
    encoder.set_color(png::ColorType::Rgba);
    encoder
        .write_header()
        .unwrap()
        .write_image_data(&data)
        .unwrap();
    let out = gradmesh(&["vectorise", s(&input), "-o", s(&json), "--points", "60"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = gradmesh::formats::read_path(&json).unwrap();
    let view = doc.view.expect("the picture's rectangle as the view");
    assert_eq!((view.x0, view.y0, view.x1, view.y1), (0.0, 0.0, 90.0, 60.0));
    let out = gradmesh(&["render", s(&json), "-o", s(&out_png)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&out_png).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    assert_eq!(reader.info().size(), (w, h));
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut pixels).unwrap();
    // The corners are far outside the disc, its centre inside.
    let alpha = |x: u32, y: u32| pixels[4 * (y * w + x) as usize + 3];
    assert_eq!(
        [
            alpha(0, 0),
            alpha(w - 1, 0),
            alpha(0, h - 1),
            alpha(w - 1, h - 1)
        ],
        [0; 4]
    );
    assert_eq!(alpha(50, 30), 255);
}
