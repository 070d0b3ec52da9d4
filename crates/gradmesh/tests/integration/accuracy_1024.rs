//! The fast path against the reference mode on every example and every real file, 1024 pixels
//! wide, in f32 (finer than 16-bit output, so rounding hides nothing): at most 0.5 CIEDE2000 on
//! any pixel at least two pixels inside the outline, at most 0.05 on average.
//!
//! Slow (about two minutes in release mode): `cargo test --release -p gradmesh --test integration
//! accuracy_1024 -- --ignored --nocapture` prints the figures of each file.
//! `GRADMESH_PLAN_FROM_BOUNDS=1` checks the fast path with
//! [`RenderOptions::plan_from_bounds`] set.

use std::path::{Path, PathBuf};

use gradmesh::formats::read_path;
use gradmesh::render::{render_document, Image, RenderOptions};
use gradmesh::ColourSpace;
use gradmesh::Document;
use palette::color_difference::Ciede2000;
use palette::{white_point::D65, Lab};

fn delta_e(a: [f32; 4], b: [f32; 4]) -> f64 {
    let lab = |p: [f32; 4]| {
        let c =
            ColourSpace::Srgb.convert(ColourSpace::Lab, [p[0] as f64, p[1] as f64, p[2] as f64]);
        Lab::<D65, f64>::new(c[0], c[1], c[2])
    };
    lab(a).difference(lab(b))
}

/// Whether pixel (x, y) and every pixel within `margin` of it is opaque in `img`.
fn inside(img: &Image, x: i64, y: i64, margin: i64) -> bool {
    (-margin..=margin).all(|dy| {
        (-margin..=margin).all(|dx| {
            let (px, py) = (x + dx, y + dy);
            px >= 0
                && py >= 0
                && px < img.width as i64
                && py < img.height as i64
                && img.pixel(px as u32, py as u32)[3] >= 1.0
        })
    })
}

fn inputs() -> Vec<(String, Vec<PathBuf>)> {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let mut out = Vec::new();
    for dir in [root.join("examples"), crate::realdata::dir()] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "json" || e == "off"))
            .collect();
        files.sort();
        for f in files {
            out.push((
                f.file_name().unwrap().to_string_lossy().into_owned(),
                vec![f],
            ));
        }
    }
    out
}

#[test]
#[ignore = "slow: run with --release -- --ignored"]
fn fast_path_matches_reference_at_1024_on_every_file() {
    compare_at(1024, None, "");
}

/// Interpolated in the other working spaces (the sRGB ones measure colour through derivatives
/// to Lab, linear and quadratic pieces alike).
#[test]
#[ignore = "slow: run with --release -- --ignored"]
fn fast_path_matches_reference_in_other_spaces() {
    for space in [
        ColourSpace::Srgb,
        ColourSpace::SrgbLinear,
        ColourSpace::Oklab,
    ] {
        for name in ["Glasses.off", "irregular-vertex.json", "edge-kinds.json"] {
            compare_at(700, Some(space), name);
        }
    }
}

/// Small images make the real meshes dense for their size: the fast path then starts from
/// level 2 or 1 instead of 3 (fewer than 64 pixels per level-3 face), and must still match.
#[test]
#[ignore = "slow: run with --release -- --ignored"]
fn fast_path_matches_reference_on_dense_meshes() {
    compare_at(160, None, "");
    compare_at(256, None, "");
}

/// Compares the files whose name contains `only` (and `GRADMESH_ONLY`, if set).
fn compare_at(size: u32, space: Option<ColourSpace>, only: &str) {
    let mut failures = Vec::new();
    // GRADMESH_ONLY=NAME checks only the files whose name contains NAME.
    let env_only = std::env::var("GRADMESH_ONLY").unwrap_or_default();
    let wanted = |n: &str| n.contains(only) && n.contains(&env_only);
    for (name, files) in inputs().into_iter().filter(|(n, _)| wanted(n)) {
        let mut doc = Document::default();
        for f in &files {
            doc.layers.extend(read_path(f).unwrap().layers);
        }
        let mut opts = RenderOptions::fit(&doc, size);
        opts.dither = false;
        opts.colour_space_override = space;
        opts.plan_from_bounds = std::env::var_os("GRADMESH_PLAN_FROM_BOUNDS").is_some();
        let fast = render_document(&doc, &opts).unwrap();
        opts.reference = true;
        let reference = render_document(&doc, &opts).unwrap();
        let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0usize);
        for y in 0..fast.height {
            for x in 0..fast.width {
                if inside(&reference, x as i64, y as i64, 2) && inside(&fast, x as i64, y as i64, 2)
                {
                    let d = delta_e(fast.pixel(x, y), reference.pixel(x, y));
                    max = max.max(d);
                    sum += d;
                    n += 1;
                }
            }
        }
        let mean = sum / n.max(1) as f64;
        let name = match space {
            Some(space) => format!("{name} in {space:?}"),
            None => name,
        };
        println!("{name} at {size}: {n} pixels, max {max:.3}, mean {mean:.4} CIEDE2000");
        if max > 0.5 || mean > 0.05 {
            failures.push(format!("{name} at {size}: max {max:.3}, mean {mean:.4}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
