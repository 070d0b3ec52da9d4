//! `vectorise` and `fit_colours`: pictures into meshes, known meshes back from their renders,
//! and hostile files.

use gradmesh::render::{render_document, RenderOptions, View};
use gradmesh::{
    fit_colours, psnr, vectorise, ColourSpace, Document, ErrorKind, GradientMesh, Quality,
    RgbaImage, VectoriseOptions,
};
use kurbo::Point;

/// The f32 render of `doc` over `0..w` x `0..h`, one pixel per unit.
fn render(doc: &Document, w: u32, h: u32) -> RgbaImage {
    let opts = RenderOptions::new(w, h, View::new(0.0, 0.0, w as f64, h as f64));
    let image = render_document(doc, &opts).unwrap();
    RgbaImage {
        width: w,
        height: h,
        pixels: image
            .data
            .chunks_exact(4)
            .map(|p| [p[0], p[1], p[2], p[3]])
            .collect(),
    }
}

/// A 4 x 3 grid of quads over `0..120` x `0..90` with smoothly varying Lab colours, all
/// inside the sRGB gamut (the renderer maps others, which no fit in Lab can then match).
fn grid_mesh() -> GradientMesh {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    for j in 0..4 {
        for i in 0..5 {
            let (x, y) = (i as f64, j as f64);
            m.add_point(
                Point::new(30.0 * x, 30.0 * y),
                [40.0 + 6.0 * x + 3.0 * y, 6.0 * (x - 2.0), 14.0 - 8.0 * y],
            );
        }
    }
    for j in 0..3 {
        for i in 0..4 {
            let a = 5 * j + i;
            m.add_face(vec![a, a + 1, a + 6, a + 5]);
        }
    }
    m
}

/// A flat picture is one colour everywhere: the fit renders it back above 40 dB.
#[test]
fn a_flat_picture_fits_above_40_db() {
    let image = RgbaImage::filled(97, 61, [0.8, 0.35, 0.1, 1.0]);
    let options = VectoriseOptions {
        points: Some(64),
        ..VectoriseOptions::default()
    };
    let v = vectorise(&image, &options).unwrap();
    assert!(v.points <= 64 && v.points >= 4, "{} points", v.points);
    assert!(v.psnr > 40.0, "{} dB", v.psnr);
}

/// The colours of a mesh fitted to its own render (the renderer's f32 output, same topology
/// and geometry) come back within a small fraction of a Lab unit: the fit's sampling of the
/// surface agrees with the renderer's.
#[test]
fn fit_colours_recovers_a_rendered_mesh() {
    let truth = grid_mesh();
    let image = render(&Document::new(vec![truth.clone()]), 120, 90);
    let mut mesh = truth.clone();
    for p in &mut mesh.points {
        p.colour = [50.0, 0.0, 0.0];
    }
    let model_psnr = fit_colours(&mut mesh, &image, Quality::Best).unwrap();
    assert!(model_psnr > 45.0, "{model_psnr} dB");
    let worst = mesh
        .points
        .iter()
        .zip(&truth.points)
        .flat_map(|(a, b)| (0..3).map(move |k| (a.colour[k] - b.colour[k]).abs()))
        .fold(0.0, f64::max);
    assert!(worst < 0.5, "largest colour difference {worst}");
}

/// Round trip: a known mesh rendered to a picture, vectorised with at most twice its points,
/// renders back above 40 dB.
#[test]
fn a_rendered_mesh_vectorises_back() {
    let mesh = grid_mesh();
    let image = render(&Document::new(vec![mesh]), 120, 90);
    let options = VectoriseOptions {
        points: Some(40),
        ..VectoriseOptions::default()
    };
    let v = vectorise(&image, &options).unwrap();
    assert!(v.points <= 40);
    assert!(v.psnr > 40.0, "{} dB with {} points", v.psnr, v.points);
    // The document covers the picture: its render at the picture's size has no hole.
    let back = render(&v.document, 120, 90);
    assert!(back.pixels.iter().all(|p| p[3] > 0.99));
    // Its mesh spans the picture: the document needs no view of its own.
    assert_eq!(v.document.view, None);
    assert!((psnr(&image, &back).unwrap() - v.psnr).abs() < 1.0);
}

/// Noise has no structure: the fit still ends within its budget, with no panic.
#[test]
fn noise_stays_within_the_budget() {
    let mut state = 12345u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state % 256) as f32 / 255.0
    };
    let pixels = (0..80 * 50)
        .map(|_| [next(), next(), next(), 1.0])
        .collect();
    let image = RgbaImage {
        width: 80,
        height: 50,
        pixels,
    };
    for quality in [Quality::Fast, Quality::Default] {
        let options = VectoriseOptions {
            points: Some(150),
            quality,
            ..VectoriseOptions::default()
        };
        let v = vectorise(&image, &options).unwrap();
        assert!(v.points <= 150 && v.points > 4);
        assert!(v.psnr.is_finite());
    }
}

/// The PSNR goal stops the refinement: a smooth picture needs few points for 30 dB.
#[test]
fn a_psnr_goal_stops_early() {
    let image = render(&Document::new(vec![grid_mesh()]), 120, 90);
    let options = VectoriseOptions {
        psnr: Some(30.0),
        ..VectoriseOptions::default()
    };
    let v = vectorise(&image, &options).unwrap();
    assert!(v.psnr > 29.0, "{} dB", v.psnr);
    assert!(v.points < 200, "{} points", v.points);
}

/// A PNG chunk: length, type and data, CRC.
fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut body = kind.to_vec();
    body.extend(data);
    let mut crc = flate2::Crc::new();
    crc.update(&body);
    let mut bytes = (data.len() as u32).to_be_bytes().to_vec();
    bytes.extend(body);
    bytes.extend(crc.sum().to_be_bytes());
    bytes
}

/// A PNG file that claims `width` x `height` RGB pixels and holds a few bytes of data.
fn png_header(width: u32, height: u32) -> Vec<u8> {
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    let mut bytes = b"\x89PNG\r\n\x1a\n".to_vec();
    bytes.extend(chunk(b"IHDR", &ihdr));
    bytes.extend(chunk(b"IDAT", &[0x78, 0x9c, 0x03, 0x00]));
    bytes.extend(chunk(b"IEND", &[]));
    bytes
}

/// A small real PNG.
fn small_png() -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, 8, 8);
    encoder.set_color(png::ColorType::Rgba);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(&[128; 8 * 8 * 4]).unwrap();
    writer.finish().unwrap();
    bytes
}

/// Files that are not pictures, cut short, empty or huge give clear errors, never a panic,
/// and a huge size is refused from the header before anything is decoded.
#[test]
fn hostile_files_give_clear_errors() {
    let limit = gradmesh::MAX_IMAGE_PIXELS;
    let message = |bytes: &[u8]| RgbaImage::decode(bytes, limit).unwrap_err().to_string();
    assert!(message(b"").contains("not a PNG or JPEG"));
    assert!(message(b"{\"layers\": []}").contains("not a PNG or JPEG"));
    let huge = RgbaImage::decode(&png_header(50_000, 50_000), limit).unwrap_err();
    assert!(
        matches!(huge.kind, ErrorKind::LimitExceeded { found, .. } if found == 2_500_000_000),
        "{huge}"
    );
    assert!(message(&png_header(0, 0)).contains("PNG image"));
    let png = small_png();
    assert_eq!(RgbaImage::decode(&png, limit).unwrap().width, 8);
    for cut in [9, 20, 33, png.len() - 13] {
        assert!(message(&png[..cut]).contains("PNG image"), "cut at {cut}");
    }
    let jpeg = std::fs::read(crate::realdata::image("rocket.jpg")).unwrap();
    let decoded = RgbaImage::decode(&jpeg, limit).unwrap();
    assert_eq!((decoded.width, decoded.height), (640, 427));
    for cut in [3, 100, 600] {
        assert!(message(&jpeg[..cut]).contains("JPEG image"), "cut at {cut}");
    }
    // A picture above a small limit is refused.
    let small = RgbaImage::decode(&jpeg, 1000).unwrap_err();
    assert!(
        matches!(small.kind, ErrorKind::LimitExceeded { .. }),
        "{small}"
    );
}

/// Options that cannot be met are refused with the option's name.
#[test]
fn bad_options_are_refused() {
    let image = RgbaImage::filled(10, 10, [0.5, 0.5, 0.5, 1.0]);
    let few = VectoriseOptions {
        points: Some(3),
        ..VectoriseOptions::default()
    };
    assert!(vectorise(&image, &few)
        .unwrap_err()
        .to_string()
        .contains("points"));
    let nan = VectoriseOptions {
        psnr: Some(f64::NAN),
        ..VectoriseOptions::default()
    };
    assert!(vectorise(&image, &nan)
        .unwrap_err()
        .to_string()
        .contains("psnr"));
    let empty = RgbaImage::filled(0, 10, [0.0; 4]);
    assert!(vectorise(&empty, &VectoriseOptions::default()).is_err());
}

/// A `w` x `h` picture whose pixel at centre `(x, y)` is `colour_at(x, y)`.
fn picture(w: u32, h: u32, colour_at: impl Fn(f64, f64) -> [f32; 4]) -> RgbaImage {
    let pixels = (0..w * h)
        .map(|i| colour_at((i % w) as f64 + 0.5, (i / w) as f64 + 0.5))
        .collect();
    RgbaImage {
        width: w,
        height: h,
        pixels,
    }
}

/// A picture of two colours split by a slanted line that no cell side follows.
fn slanted_edge(w: u32, h: u32) -> RgbaImage {
    picture(w, h, |x, y| {
        if x + 0.3 * y < 0.45 * w as f64 {
            [0.85, 0.55, 0.2, 1.0]
        } else {
            [0.15, 0.25, 0.6, 1.0]
        }
    })
}

/// Moving the points cuts the error where the picture has an edge between cell corners; the
/// moved mesh has no fold, covers the picture, keeps the points on its sides on them and its
/// corners at the picture's.
#[test]
fn moving_points_follows_an_edge() {
    let image = slanted_edge(96, 64);
    let run = |fit_positions: bool| {
        let options = VectoriseOptions {
            points: Some(60),
            fit_positions,
            ..VectoriseOptions::default()
        };
        vectorise(&image, &options).unwrap()
    };
    let (fixed, moved) = (run(false), run(true));
    assert!(
        moved.psnr > fixed.psnr + 2.0,
        "moved {} dB, fixed {} dB",
        moved.psnr,
        fixed.psnr
    );
    let mesh = &moved.document.layers[0];
    let fixed_mesh = &fixed.document.layers[0];
    assert_eq!(mesh.points.len(), fixed_mesh.points.len());
    let shifted = mesh
        .points
        .iter()
        .zip(&fixed_mesh.points)
        .filter(|(a, b)| a.position.distance(b.position) > 0.1)
        .count();
    assert!(shifted > 0, "no point moved");
    assert!(gradmesh::render::find_folds(mesh).unwrap().is_empty());
    for p in &mesh.points {
        let q = p.position;
        assert!(
            (0.0..=96.0).contains(&q.x) && (0.0..=64.0).contains(&q.y),
            "{q:?}"
        );
    }
    for corner in [(0.0, 0.0), (96.0, 0.0), (96.0, 64.0), (0.0, 64.0)] {
        let corner = Point::new(corner.0, corner.1);
        assert!(
            mesh.points.iter().any(|p| p.position == corner),
            "{corner:?}"
        );
    }
    let back = render(&moved.document, 96, 64);
    assert!(back.pixels.iter().all(|p| p[3] > 0.99));
}

/// Discs of three colours and a slanted edge on a background: edges that need cells down to
/// the smallest size to follow.
fn discs_and_edge(w: u32, h: u32) -> RgbaImage {
    let discs = [
        (30.0, 28.0, 17.0, [0.9, 0.2, 0.2]),
        (70.0, 60.0, 21.0, [0.2, 0.7, 0.3]),
        (24.0, 74.0, 11.0, [0.95, 0.9, 0.2]),
    ];
    picture(w, h, |x, y| {
        let inside = discs
            .iter()
            .find(|(cx, cy, r, _)| (x - cx).hypot(y - cy) < *r);
        let [r, g, b] = match inside {
            Some(&(.., colour)) => colour,
            None if x - 0.4 * y > 0.55 * w as f64 => [0.1, 0.15, 0.5],
            None => [0.8, 0.8, 0.75],
        };
        [r, g, b, 1.0]
    })
}

/// A larger budget fits at least as well: a starting grid whose cells cannot halve down to
/// the 3 px floor (10.7 px cells stop at 5.3 px) would fit these edges worse with 400 points
/// than with 320.
#[test]
fn a_larger_budget_fits_edges_no_worse() {
    let image = discs_and_edge(96, 96);
    let fit = |points: usize| {
        let options = VectoriseOptions {
            points: Some(points),
            fit_positions: false,
            round_output: false,
            ..VectoriseOptions::default()
        };
        vectorise(&image, &options).unwrap().psnr
    };
    let (smaller, larger) = (fit(320), fit(400));
    assert!(
        larger >= smaller - 0.05,
        "400 points {larger:.2} dB, 320 points {smaller:.2} dB"
    );
}

/// A picture with smooth shading and a soft slanted edge, as photographs have.
fn shaded_picture(w: u32, h: u32) -> RgbaImage {
    picture(w, h, |x, y| {
        let (x, y) = (x as f32, y as f32);
        let (u, v) = (x / w as f32, y / h as f32);
        let edge = 1.0 / (1.0 + (-(x - 0.6 * y - 0.3 * w as f32) / 2.0).exp());
        let wave = 0.5 + 0.5 * (6.0 * u + 3.0 * v).sin();
        [
            0.2 + 0.6 * edge * u + 0.1 * wave,
            0.3 + 0.4 * v * (1.0 - edge) + 0.2 * wave,
            0.7 - 0.5 * edge + 0.1 * u,
            1.0,
        ]
    })
}

/// Every number in `text` in the lists after `key` (`"position": [..]`).
fn numbers_after(text: &str, key: &str) -> Vec<f64> {
    text.match_indices(key)
        .flat_map(|(at, _)| {
            let rest = &text[at + key.len()..];
            let list = &rest[..rest.find(']').expect("a closed list")];
            list.split(',')
                .map(|n| n.trim().parse::<f64>().expect("a number"))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// `picture` vectorised with 150 points, rounded and not: neither folds, the rounded document
/// renders within 0.1 dB of the unrounded one, its file is under three quarters of the size;
/// returns its positions and colours as written.
fn rounded_against_unrounded(picture: &RgbaImage) -> (Vec<f64>, Vec<f64>) {
    let run = |round_output: bool| {
        let options = VectoriseOptions {
            points: Some(150),
            round_output,
            ..VectoriseOptions::default()
        };
        vectorise(picture, &options).unwrap()
    };
    let (exact, rounded) = (run(false), run(true));
    assert!(
        (exact.psnr - rounded.psnr).abs() < 0.1,
        "rounded {} dB, unrounded {} dB",
        rounded.psnr,
        exact.psnr
    );
    let exact_text = gradmesh::formats::json::write_document(&exact.document);
    let text = gradmesh::formats::json::write_document(&rounded.document);
    assert!(
        text.len() < exact_text.len() * 3 / 4,
        "rounded {} bytes, unrounded {} bytes",
        text.len(),
        exact_text.len()
    );
    let exact_folds = gradmesh::render::find_folds(&exact.document.layers[0]).unwrap();
    let folds = gradmesh::render::find_folds(&rounded.document.layers[0]).unwrap();
    assert!(exact_folds.is_empty() && folds.is_empty(), "{folds:?}");
    let (w, h) = (picture.width, picture.height);
    let back = render(&rounded.document, w, h);
    assert!((psnr(picture, &back).unwrap() - rounded.psnr).abs() < 0.5);
    let positions = numbers_after(&text, "\"position\": [");
    let colours = numbers_after(&text, "\"colour\": [");
    assert_eq!(positions.len(), 2 * rounded.points);
    assert_eq!(colours.len(), 3 * rounded.points);
    (positions, colours)
}

/// Whether `v` is a multiple of `step` (as written: the nearest double to one).
fn multiple(v: f64, step: f64) -> bool {
    ((v / step).round() * step - v).abs() < 1e-9
}

/// A smooth picture fitted above 32 dB keeps tenths of a pixel and of a Lab unit.
#[test]
fn rounded_output_of_a_close_fit_keeps_tenths() {
    let picture = shaded_picture(120, 80);
    let (positions, colours) = rounded_against_unrounded(&picture);
    assert!(positions.iter().chain(&colours).all(|&v| multiple(v, 0.1)));
    assert!(colours.iter().any(|c| c.fract() != 0.0), "{colours:?}");
}

/// The shaded picture with a grain of +-0.07 (as a photograph's texture, which no mesh of
/// its size follows), so that the fit stays below 32 dB.
fn grainy_picture(w: u32, h: u32) -> RgbaImage {
    let mut picture = shaded_picture(w, h);
    let mut state = 0x2545_f491_u32;
    for p in &mut picture.pixels {
        for c in &mut p[..3] {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            let grain = (state as f32 / u32::MAX as f32 - 0.5) * 0.14;
            *c = (*c + grain).clamp(0.0, 1.0);
        }
    }
    picture
}

/// A fit below 32 dB is written with whole Lab units and half pixels (a tenth where half
/// pixels would make points meet or faces fold, the fitted position where a tenth would),
/// within 0.1 dB of the unrounded render.
#[test]
fn rounded_output_of_a_photograph_like_fit_is_coarse() {
    let picture = grainy_picture(120, 80);
    let (positions, colours) = rounded_against_unrounded(&picture);
    assert!(colours.iter().all(|c| c.fract() == 0.0), "{colours:?}");
    let tenths = positions.iter().filter(|&&v| multiple(v, 0.1)).count();
    assert!(tenths * 50 >= positions.len() * 49, "{positions:?}");
    let halves = positions.iter().filter(|&&v| multiple(v, 0.5)).count();
    assert!(
        halves * 20 >= positions.len() * 17,
        "{halves} of {}",
        positions.len()
    );
}

/// A 160 x 120 picture: an opaque ellipse of smoothly varying colour, transparent around it,
/// and whether each pixel is inside.
fn ellipse_on_transparent() -> (RgbaImage, Vec<bool>) {
    let (w, h) = (160u32, 120u32);
    let mut pixels = Vec::new();
    let mut inside = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
            let within = ((fx - 80.0) / 62.0).powi(2) + ((fy - 60.0) / 42.0).powi(2) < 1.0;
            let colour = [0.2 + 0.6 * fx / w as f32, 0.3 + 0.5 * fy / h as f32, 0.5];
            pixels.push([
                colour[0],
                colour[1],
                colour[2],
                if within { 1.0 } else { 0.0 },
            ]);
            inside.push(within);
        }
    }
    (
        RgbaImage {
            width: w,
            height: h,
            pixels,
        },
        inside,
    )
}

/// Transparent pixels are outside: the mesh covers the opaque ellipse alone, its outline on
/// the ellipse's edge, and the colours inside match.
#[test]
fn a_transparent_background_is_left_out() {
    let (image, inside) = ellipse_on_transparent();
    let options = VectoriseOptions {
        points: Some(120),
        ..VectoriseOptions::default()
    };
    let v = vectorise(&image, &options).unwrap();
    assert!(v.points <= 120, "{} points", v.points);
    let back = render(&v.document, image.width, image.height);
    let covered: Vec<bool> = back.pixels.iter().map(|p| p[3] >= 0.5).collect();
    let both = covered
        .iter()
        .zip(&inside)
        .filter(|(c, i)| **c && **i)
        .count();
    let either = covered
        .iter()
        .zip(&inside)
        .filter(|(c, i)| **c || **i)
        .count();
    let overlap = both as f64 / either as f64;
    assert!(overlap > 0.97, "covered and inside overlap {overlap}");
    let view = v.document.view.expect("the picture's rectangle");
    assert_eq!(
        (view.x0, view.y0, view.x1, view.y1),
        (0.0, 0.0, 160.0, 120.0)
    );
    // Over the picture as it is (transparent pixels count as black in both), and the colours
    // where both are opaque.
    assert!(v.psnr > 25.0, "{} dB", v.psnr);
    let (mut sum, mut n) = (0.0, 0);
    for ((p, q), (&c, &i)) in image
        .pixels
        .iter()
        .zip(&back.pixels)
        .zip(covered.iter().zip(&inside))
    {
        if c && i {
            sum += (0..3)
                .map(|k| ((p[k] - q[k]) as f64 * 255.0).powi(2))
                .sum::<f64>();
            n += 3;
        }
    }
    let inside_psnr = 10.0 * (255.0f64.powi(2) * n as f64 / sum).log10();
    assert!(inside_psnr > 35.0, "{inside_psnr} dB where both are opaque");
}

/// A picture with no opaque pixel has nothing to trace: a clear error.
#[test]
fn a_wholly_transparent_picture_is_refused() {
    let image = RgbaImage::filled(40, 30, [0.5, 0.5, 0.5, 0.0]);
    let e = vectorise(&image, &VectoriseOptions::default()).unwrap_err();
    assert!(e.to_string().contains("transparent"), "{e}");
}

/// Opacity as noise (a checkerboard of opaque and transparent pixels, and random ones): the
/// fit stays within its budget and gives a valid mesh, or says the opaque part is too small.
#[test]
fn scattered_opacity_stays_within_the_budget() {
    let (w, h) = (48u32, 32u32);
    let mut state = 7u64;
    let mut random = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) as u32
    };
    let checkerboard = |x: u32, y: u32| (x + y) % 2 == 0;
    let pictures = [
        (0..w * h)
            .map(|i| checkerboard(i % w, i / w))
            .collect::<Vec<_>>(),
        (0..w * h).map(|_| random() % 3 == 0).collect(),
        (0..w * h)
            .map(|i| checkerboard(i % w / 8, i / w / 8))
            .collect(),
    ];
    for opaque in pictures {
        let image = RgbaImage {
            width: w,
            height: h,
            pixels: opaque
                .iter()
                .map(|&o| [0.3, 0.6, 0.2, if o { 1.0 } else { 0.0 }])
                .collect(),
        };
        let options = VectoriseOptions {
            points: Some(40),
            quality: Quality::Fast,
            ..VectoriseOptions::default()
        };
        match vectorise(&image, &options) {
            Ok(v) => {
                assert!(v.points <= 40, "{} points", v.points);
                gradmesh::validate(&v.document.layers[0]).expect("a valid mesh");
            }
            Err(e) => assert!(e.to_string().contains("too small to trace"), "{e}"),
        }
    }
}
