//! Renders meshes with the paper's variants side by side (the ternary step, the ternary step
//! with interpolated positions, two binary steps) and measures how far each is from the
//! ternary step in CIEDE2000, over the pixels both cover fully.
//!
//! Run from the repository root:
//! `cargo run --release -p gradmesh --example compare_variants`
//! It writes `docs/gallery/variants/*.png` and prints the table of `docs/variants.md`.

use std::path::Path;

use gradmesh::formats::read_path;
use gradmesh::render::{encode_png, render_document, Image, PngDepth, RenderOptions};
use gradmesh::ColourSpace;
use gradmesh::{Document, FirstStep};
use palette::color_difference::Ciede2000;
use palette::{white_point::D65, Lab};

const WIDTH: u32 = 300;

fn variants(doc: &Document) -> [(&'static str, Document); 3] {
    let with = |f: &dyn Fn(&mut gradmesh::GradientMesh)| {
        let mut d = doc.clone();
        d.layers.iter_mut().for_each(f);
        d
    };
    [
        ("ternary", doc.clone()),
        ("interpolated", with(&|m| m.interpolate_positions = true)),
        ("binary", with(&|m| m.first_step = FirstStep::Binary)),
    ]
}

/// Mean, 99th percentile and maximum CIEDE2000 between two renders, over pixels opaque in both.
fn difference(a: &Image, b: &Image) -> (f64, f64, f64) {
    let lab = |p: [f32; 4]| {
        let c =
            ColourSpace::Srgb.convert(ColourSpace::Lab, [p[0] as f64, p[1] as f64, p[2] as f64]);
        Lab::<D65, f64>::new(c[0], c[1], c[2])
    };
    let mut d = Vec::new();
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.pixel(x, y), b.pixel(x, y));
            if p[3] >= 0.999 && q[3] >= 0.999 {
                d.push(lab(p).difference(lab(q)));
            }
        }
    }
    d.sort_by(f64::total_cmp);
    let mean = d.iter().sum::<f64>() / d.len().max(1) as f64;
    let p99 = d.get(d.len() * 99 / 100).copied().unwrap_or(0.0);
    (mean, p99, d.last().copied().unwrap_or(0.0))
}

fn main() -> Result<(), gradmesh::Error> {
    let out = Path::new("docs/gallery/variants");
    std::fs::create_dir_all(out)
        .map_err(|e| gradmesh::Error::new(gradmesh::ErrorKind::Io(e.to_string())))?;
    let real = Path::new("../shared/realdata/gradientmeshimproved-off");
    let inputs: Vec<(&str, Vec<std::path::PathBuf>)> = vec![
        (
            "sparse-irregular",
            vec!["examples/sparse-irregular.json".into()],
        ),
        (
            "irregular-vertex-spread",
            vec!["examples/irregular-vertex-spread.json".into()],
        ),
        ("handles-long", vec!["examples/handles-long.json".into()]),
        ("rectangle", vec!["examples/rectangle.json".into()]),
        ("glasses", vec![real.join("Glasses.off")]),
        (
            "paprika",
            [
                "Paprika_Paprika_layer2.off",
                "Paprika_Paprika_layer1.off",
                "Paprika_Paprika_layer0.off",
            ]
            .iter()
            .map(|f| real.join(f))
            .collect(),
        ),
    ];
    println!("| mesh | interpolated vs ternary (mean / 99% / max) | binary vs ternary (mean / 99% / max) |");
    println!("|---|---|---|");
    for (name, files) in inputs {
        let mut doc = Document::default();
        for f in &files {
            doc.layers.extend(read_path(f)?.layers);
        }
        // Transparent, so that "opaque in both" means "covered by both".
        let opts = RenderOptions::fit(&doc, WIDTH);
        let mut images = Vec::new();
        for (variant, d) in variants(&doc) {
            let image = render_document(&d, &opts)?;
            let png = encode_png(&image, PngDepth::Eight { dither: true })?;
            std::fs::write(out.join(format!("{name}-{variant}.png")), png)
                .map_err(|e| gradmesh::Error::new(gradmesh::ErrorKind::Io(e.to_string())))?;
            images.push(image);
        }
        let f = |(m, p, x): (f64, f64, f64)| format!("{m:.2} / {p:.2} / {x:.2}");
        println!(
            "| {name} | {} | {} |",
            f(difference(&images[1], &images[0])),
            f(difference(&images[2], &images[0]))
        );
    }
    Ok(())
}
