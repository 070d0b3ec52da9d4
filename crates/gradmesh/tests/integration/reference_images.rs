//! Reference-image tests in the style of resvg: every example in `examples/` and the real
//! artwork are rendered and compared with a checked-in PNG in `tests/references/`.
//!
//! * A pixel passes when every channel is within `TOLERANCE` of the reference (8-bit units);
//!   the test fails if any pixel does not, and writes `target/reference-diffs/<name>.png`
//!   (expected | difference | actual) to look at.
//! * `GRADMESH_BLESS=1 cargo test --test integration reference_images` rewrites the references
//!   from the current renderer. Look at them before committing.

use std::path::{Path, PathBuf};

use gradmesh::formats::read_path;
use gradmesh::render::{render_document, Image, RenderOptions};
use gradmesh::Document;

use crate::realdata;

/// Largest difference per channel, in 8-bit units, between a rendering and its reference.
const TOLERANCE: u8 = 2;
/// Width of the test renderings (small, to keep the suite fast).
const WIDTH: u32 = 160;

fn repo() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn references() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/references"))
}

/// Decodes an 8-bit RGBA PNG.
fn decode(path: &Path) -> Option<(u32, u32, Vec<u8>)> {
    let file = std::fs::File::open(path).ok()?;
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .ok()?;
    let mut buf = vec![0; reader.output_buffer_size()?];
    let info = reader.next_frame(&mut buf).ok()?;
    assert_eq!(info.color_type, png::ColorType::Rgba, "{}", path.display());
    assert_eq!(info.bit_depth, png::BitDepth::Eight, "{}", path.display());
    buf.truncate(info.buffer_size());
    Some((info.width, info.height, buf))
}

fn encode(path: &Path, width: u32, height: u32, data: &[u8]) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .unwrap()
        .write_image_data(data)
        .unwrap();
}

/// Renders `doc` over white, without dithering (so that references are stable).
fn render(doc: &Document) -> (u32, u32, Vec<u8>) {
    let mut opts = RenderOptions::fit(doc, WIDTH);
    opts.background = Some([1.0, 1.0, 1.0, 1.0]);
    opts.dither = false;
    let image: Image = render_document(doc, &opts).unwrap();
    (image.width, image.height, image.to_u8(false))
}

/// Compares a rendering with its reference, or blesses it.
fn check(name: &str, doc: &Document) {
    let (w, h, actual) = render(doc);
    let reference = references().join(format!("{name}.png"));
    if std::env::var_os("GRADMESH_BLESS").is_some() {
        encode(&reference, w, h, &actual);
        return;
    }
    let Some((rw, rh, expected)) = decode(&reference) else {
        panic!(
            "{name}: no reference at {}; run with GRADMESH_BLESS=1 to create it",
            reference.display()
        );
    };
    assert_eq!((rw, rh), (w, h), "{name}: size");
    let mut bad = 0usize;
    let mut worst = 0u8;
    let mut diff = vec![255u8; actual.len()];
    for (i, (a, e)) in actual.iter().zip(&expected).enumerate() {
        let d = a.abs_diff(*e);
        worst = worst.max(d);
        if i % 4 != 3 {
            diff[i] = 255 - d.saturating_mul(16);
        }
        if d > TOLERANCE {
            bad += 1;
        }
    }
    if bad > 0 {
        // expected | difference (x16, dark is different) | actual, side by side.
        let row = 4 * w as usize;
        let mut panel = Vec::with_capacity(3 * actual.len());
        for y in 0..h as usize {
            for img in [&expected, &diff, &actual] {
                panel.extend_from_slice(&img[y * row..(y + 1) * row]);
            }
        }
        let out = repo()
            .join("target/reference-diffs")
            .join(format!("{name}.png"));
        encode(&out, 3 * w, h, &panel);
        panic!(
            "{name}: {bad} channel values differ by more than {TOLERANCE} (worst {worst}); see {}",
            out.display()
        );
    }
}

fn example(name: &str) {
    let doc = read_path(&repo().join("examples").join(format!("{name}.json"))).unwrap();
    check(name, &doc);
}

fn real(name: &str, files: &[&str]) {
    let mut doc = Document::default();
    for f in files {
        doc.layers
            .extend(read_path(&realdata::path(f)).unwrap().layers);
    }
    check(name, &doc);
}

macro_rules! examples {
    ($($test:ident => $name:literal),* $(,)?) => {
        $(#[test] fn $test() { example($name) })*
        /// Every example file has a test above.
        #[test]
        fn every_example_has_a_test() {
            let mut names: Vec<String> = std::fs::read_dir(repo().join("examples"))
                .unwrap()
                .filter_map(|e| {
                    let p = e.unwrap().path();
                    (p.extension()? == "json").then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
                })
                .collect();
            names.sort();
            let mut tested = vec![$($name.to_string()),*];
            tested.sort();
            assert_eq!(names, tested);
        }
    };
}

examples! {
    annulus => "annulus",
    edge_kinds => "edge-kinds",
    fold => "fold",
    fold_fixed => "fold-fixed",
    handles_long => "handles-long",
    handles_short => "handles-short",
    irregular_vertex => "irregular-vertex",
    irregular_vertex_spread => "irregular-vertex-spread",
    multires => "multires",
    non_rectangular => "non-rectangular",
    rectangle => "rectangle",
    sparse_irregular => "sparse-irregular",
}

#[test]
fn tucan() {
    real(
        "tucan",
        &[
            "Tucan_Tucan_Layer5.off",
            "Tucan_Tucan_Layer4.off",
            "Tucan_Tucan_Layer3.off",
            "Tucan_Tucan_Layer2.off",
            "Tucan_Tucan_Layer1.off",
            "Tucan_Tucan_Layer0.off",
        ],
    );
}

#[test]
fn paprika() {
    real(
        "paprika",
        &[
            "Paprika_Paprika_layer2.off",
            "Paprika_Paprika_layer1.off",
            "Paprika_Paprika_layer0.off",
        ],
    );
}

#[test]
fn glasses() {
    real("glasses", &["Glasses.off"]);
}
