//! The renderer against the paper's conditions, a reference rendering, exact coverage and itself.
//!
//! Set `GRADMESH_TEST_PNG_DIR` to a directory to get the images of these tests as PNG files.

use std::collections::BTreeMap;

use gradmesh::render::{
    draw_outlines, encode_png, find_folds, render_document, render_image, BlendSpace, GamutMapping,
    Image, PngDepth, RenderOptions, View,
};
use gradmesh::{ColourSpace, Document, EdgeKind, GradientMesh, Refinement, WedgeOverride};
use kurbo::{Point, Vec2};
use palette::color_difference::Ciede2000;
use palette::{white_point::D65, Lab};

use crate::realdata;

// ---------------------------------------------------------------------------------------------
// Meshes

/// An `n` x `m` grid of quads over `[x0, x1] x [y0, y1]`, rotated by `angle` about its centre,
/// with colours from `colour(i, j)` (CIE Lab).
fn grid(
    n: u32,
    m: u32,
    rect: [f64; 4],
    angle: f64,
    colour: impl Fn(u32, u32) -> [f64; 3],
) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    let [x0, y0, x1, y1] = rect;
    let c = Point::new(0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (s, co) = angle.sin_cos();
    for j in 0..=m {
        for i in 0..=n {
            let p = Point::new(
                x0 + (x1 - x0) * i as f64 / n as f64,
                y0 + (y1 - y0) * j as f64 / m as f64,
            );
            let d = p - c;
            let q = c + Vec2::new(co * d.x - s * d.y, s * d.x + co * d.y);
            mesh.add_point(q, colour(i, j));
        }
    }
    let v = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..m {
        for i in 0..n {
            mesh.add_face(vec![v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    mesh
}

/// Colours well inside the sRGB gamut, varying over the grid.
fn soft_colour(i: u32, j: u32) -> [f64; 3] {
    let t = (i * 7 + j * 13) as f64;
    [
        45.0 + 30.0 * ((t * 0.37).sin() * 0.5 + 0.5),
        20.0 * (t * 0.71).cos(),
        20.0 * (t * 0.53).sin(),
    ]
}

/// A five-quad star around an extraordinary vertex of valence 5.
fn star(centre: Point, radius: f64) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    let tau = std::f64::consts::TAU;
    let at = |r: f64, k: f64| {
        let a = tau * k / 5.0 - tau / 4.0;
        centre + Vec2::new(r * a.cos(), r * a.sin())
    };
    let c = mesh.add_point(centre, [90.0, 0.0, 8.0]);
    let inner: Vec<u32> = (0..5)
        .map(|k| {
            let h = tau * k as f64 / 5.0;
            mesh.add_point(
                at(0.45 * radius, k as f64),
                [65.0, 22.0 * h.cos(), 22.0 * h.sin()],
            )
        })
        .collect();
    let outer: Vec<u32> = (0..5)
        .map(|k| {
            let h = tau * (k as f64 + 0.5) / 5.0;
            mesh.add_point(
                at(radius, k as f64 + 0.5),
                [50.0, 25.0 * h.cos(), 25.0 * h.sin()],
            )
        })
        .collect();
    for k in 0..5 {
        mesh.add_face(vec![c, inner[k], outer[k], inner[(k + 1) % 5]]);
    }
    mesh
}

/// A ring of `n` quads around a hole.
fn annulus(centre: Point, r0: f64, r1: f64, n: u32) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    let tau = std::f64::consts::TAU;
    for k in 0..n {
        let a = tau * k as f64 / n as f64;
        let (s, c) = a.sin_cos();
        mesh.add_point(
            centre + Vec2::new(r0 * c, r0 * s),
            [70.0, 25.0 * c, 25.0 * s],
        );
        mesh.add_point(
            centre + Vec2::new(r1 * c, r1 * s),
            [45.0, -20.0 * s, 20.0 * c],
        );
    }
    for k in 0..n {
        let (a, b) = (2 * k, 2 * ((k + 1) % n));
        mesh.add_face(vec![a, b, b + 1, a + 1]);
    }
    mesh
}

fn doc(layers: Vec<GradientMesh>) -> Document {
    Document::new(layers)
}

// ---------------------------------------------------------------------------------------------
// Helpers

fn save(name: &str, image: &Image) {
    if let Some(dir) = std::env::var_os("GRADMESH_TEST_PNG_DIR") {
        let path = std::path::Path::new(&dir).join(format!("{name}.png"));
        std::fs::write(
            path,
            encode_png(image, PngDepth::Eight { dither: true }).unwrap(),
        )
        .unwrap();
    }
}

fn lab(c: [f64; 3]) -> Lab<D65, f64> {
    Lab::new(c[0], c[1], c[2])
}

/// CIEDE2000 between two straight-alpha sRGB pixels' colours.
fn delta_e(a: [f32; 4], b: [f32; 4]) -> f64 {
    let to_lab = |p: [f32; 4]| {
        lab(ColourSpace::Srgb.convert(ColourSpace::Lab, [p[0] as f64, p[1] as f64, p[2] as f64]))
    };
    to_lab(a).difference(to_lab(b))
}

/// Pixels whose square lies at least `margin` pixels inside the opaque region of `img`.
fn interior(img: &Image, margin: i64) -> Vec<(u32, u32)> {
    let (w, h) = (img.width as i64, img.height as i64);
    let opaque = |x: i64, y: i64| {
        x >= 0 && y >= 0 && x < w && y < h && img.pixel(x as u32, y as u32)[3] >= 1.0
    };
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let all =
                (-margin..=margin).all(|dy| (-margin..=margin).all(|dx| opaque(x + dx, y + dy)));
            if all {
                out.push((x as u32, y as u32));
            }
        }
    }
    out
}

/// The limit position of every control point of `mesh`, with its colour.
fn limit_points(mesh: &GradientMesh) -> Vec<(Point, [f64; 3])> {
    let (mut r, _) = Refinement::new(mesh, 2).unwrap();
    let data = r.evaluate();
    let lim = r.limit(&data, 2);
    (0..mesh.points.len() as u32)
        .map(|v| {
            let d = lim[r.vertex_at_level(v, 2)];
            (
                Point::new(d.position[0], d.position[1]),
                mesh.points[v as usize].colour,
            )
        })
        .collect()
}

fn to_pixel(opts: &RenderOptions, p: Point) -> (u32, u32) {
    let v = &opts.view;
    let x = (p.x - v.x0) / v.width() * opts.width as f64;
    let y = (p.y - v.y0) / v.height() * opts.height as f64;
    (
        (x.floor() as u32).min(opts.width - 1),
        (y.floor() as u32).min(opts.height - 1),
    )
}

fn test_meshes() -> Vec<(&'static str, GradientMesh)> {
    vec![
        (
            "grid",
            grid(4, 3, [0.0, 0.0, 400.0, 300.0], 0.0, soft_colour),
        ),
        ("star", star(Point::new(0.0, 0.0), 100.0)),
        ("annulus", annulus(Point::new(0.0, 0.0), 40.0, 100.0, 7)),
        (
            "tilted",
            grid(3, 3, [0.0, 0.0, 300.0, 200.0], 0.4, soft_colour),
        ),
    ]
}

// ---------------------------------------------------------------------------------------------
// Tests

/// Condition 1 of the paper, in pixels: the pixel under the limit point of each control point
/// shows that point's colour.
#[test]
fn control_colours_appear_at_their_limit_points() {
    for (name, mesh) in test_meshes() {
        let d = doc(vec![mesh.clone()]);
        let opts = RenderOptions::fit(&d, 256);
        let img = render_document(&d, &opts).unwrap();
        save(&format!("condition1-{name}"), &img);
        let mut worst = 0.0f64;
        for (p, colour) in limit_points(&mesh) {
            let (x, y) = to_pixel(&opts, p);
            let px = img.pixel(x, y);
            assert!(px[3] > 0.0, "{name}: pixel ({x}, {y}) is empty");
            let got = ColourSpace::Srgb
                .convert(ColourSpace::Lab, [px[0] as f64, px[1] as f64, px[2] as f64]);
            let e = lab(got).difference(lab(colour));
            worst = worst.max(e);
            assert!(
                e <= 0.5,
                "{name}: control colour {colour:?} shows as {got:?} (dE00 {e:.3})"
            );
        }
        eprintln!("{name}: worst dE00 at control points {worst:.4}");
    }
}

/// The fast path against the reference rendering, at 16 bits: largest and mean CIEDE2000 over
/// the interior pixels.
fn compare_with_reference(name: &str, d: &Document, max_side: u32) -> (f64, f64) {
    let mut opts = RenderOptions::fit(d, max_side);
    let (fast, info) = render_image(d, &opts).unwrap();
    opts.reference = true;
    let (reference, ref_info) = render_image(d, &opts).unwrap();
    save(&format!("fast-{name}"), &fast);
    save(&format!("reference-{name}"), &reference);
    // Compare at 16 bits.
    let q = |img: &Image| {
        let mut out = img.clone();
        out.data = img.to_u16().iter().map(|&v| v as f32 / 65535.0).collect();
        out
    };
    let (fast, reference) = (q(&fast), q(&reference));
    let pixels = interior(&reference, 2);
    assert!(
        pixels.len() > 1000,
        "{name}: {} interior pixels",
        pixels.len()
    );
    let (mut max, mut sum) = (0.0f64, 0.0);
    for &(x, y) in &pixels {
        let e = delta_e(fast.pixel(x, y), reference.pixel(x, y));
        max = max.max(e);
        sum += e;
    }
    let mean = sum / pixels.len() as f64;
    eprintln!(
        "{name}: fast level {} vs reference level {}: max dE00 {max:.4}, mean {mean:.5} over {} pixels",
        info.layers[0].level,
        ref_info.layers[0].level,
        pixels.len()
    );
    (max, mean)
}

/// The fast path against the reference rendering, at 16 bits.
#[test]
fn fast_path_matches_reference() {
    for (name, mesh) in test_meshes() {
        let (max, mean) = compare_with_reference(name, &doc(vec![mesh]), 160);
        assert!(max <= 0.5, "{name}: max dE00 {max}");
        assert!(mean <= 0.05, "{name}: mean dE00 {mean}");
    }
}

/// Meshes whose faces are not all regular B-spline patches: extraordinary vertices, corners,
/// an infinitely sharp crease ending inside, a semi-sharp crease, a discontinuous edge.
fn featured_meshes() -> Vec<(&'static str, GradientMesh)> {
    let v = |i: u32, j: u32| j * 5 + i;
    let mut creased = grid(4, 3, [0.0, 0.0, 400.0, 300.0], 0.2, soft_colour);
    creased.set_edge(v(1, 1), v(2, 1), EdgeKind::Crease, None);
    creased.set_edge(v(2, 1), v(3, 1), EdgeKind::Crease, None);
    creased.set_edge(v(2, 2), v(2, 3), EdgeKind::Crease, Some(1.5));
    let mut cut = grid(4, 3, [0.0, 0.0, 400.0, 300.0], -0.3, soft_colour);
    cut.set_edge(v(2, 0), v(2, 1), EdgeKind::Discontinuous, None);
    let mut star_crease = star(Point::new(0.0, 0.0), 100.0);
    // A semi-sharp spoke from the extraordinary centre (point 0) to an inner point.
    star_crease.set_edge(0, 1, EdgeKind::Crease, Some(2.0));
    vec![
        ("creased", creased),
        ("cut", cut),
        ("star-crease", star_crease),
    ]
}

/// The adaptive fast path (regular patches evaluated directly, other faces refined locally,
/// faces of different densities stitched) within the same tolerances of the reference mode
/// (uniform refinement) on meshes with irregular features.
#[test]
fn adaptive_path_matches_reference_on_irregular_features() {
    for (name, mesh) in featured_meshes() {
        let (max, mean) = compare_with_reference(name, &doc(vec![mesh]), 200);
        assert!(max <= 0.5, "{name}: max dE00 {max}");
        assert!(mean <= 0.05, "{name}: mean dE00 {mean}");
    }
}

/// No crack between faces of different densities: over an opaque background, every pixel whose
/// square lies inside the mesh is exactly opaque, and every interior pixel is covered by a
/// triangle, so its colour is close to the reference (a crack would show the colour of the
/// nearest boundary point instead).
#[test]
fn adaptive_path_has_no_cracks() {
    for (name, mesh) in featured_meshes().into_iter().chain(test_meshes()) {
        let d = doc(vec![mesh]);
        let mut opts = RenderOptions::fit(&d, 300);
        opts.background = Some([0.0, 0.0, 0.0, 1.0]);
        opts.dither = false;
        let img = render_document(&d, &opts).unwrap();
        opts.background = None;
        let bare = render_document(&d, &opts).unwrap();
        for (x, y) in interior(&bare, 2) {
            assert_eq!(img.pixel(x, y)[3], 1.0, "{name}: ({x}, {y})");
            assert_eq!(bare.pixel(x, y)[3], 1.0, "{name}: ({x}, {y})");
        }
    }
}

/// The default thread pool and a single thread give byte-identical images of real artwork,
/// several layers, faces of many densities.
#[test]
fn deterministic_with_default_pool() {
    let mut layers = Vec::new();
    for name in ["Tucan_Tucan_Layer3", "Tucan_Tucan_Layer1"] {
        let text = std::fs::read_to_string(realdata::path(&format!("{name}.off"))).unwrap();
        layers.push(gradmesh::formats::off::read_off(&text).unwrap());
    }
    layers.extend(featured_meshes().into_iter().map(|(_, m)| m));
    let d = doc(layers);
    let opts = RenderOptions::fit(&d, 400);
    let mut out_default = vec![0u8; 4 * opts.width as usize * opts.height as usize];
    let mut out_single = out_default.clone();
    gradmesh::render::render_document_into(&d, &opts, &mut out_default).unwrap();
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| gradmesh::render::render_document_into(&d, &opts, &mut out_single))
        .unwrap();
    assert!(out_default == out_single, "thread count changed the pixels");
}

/// A layer drawn where no layer above it shows anything gives the bytes it gives alone: the
/// drawing composites under a clear pixel exactly as it draws a layer with nothing above it
/// (both are fast paths of their own), in Lab and in sRGB with colours in range (each space
/// has its own pixel loop).
#[test]
fn a_layer_under_nothing_draws_as_it_does_alone() {
    let below = grid(6, 5, [0.0, 0.0, 120.0, 100.0], 0.2, soft_colour);
    let above = star(Point::new(30.0, 40.0), 28.0);
    // The sRGB loop without gamut search takes colours in range only.
    for p in below.points.iter().chain(&above.points) {
        let rgb = ColourSpace::Lab.convert(ColourSpace::Srgb, p.colour);
        assert!(rgb.iter().all(|c| (0.0..=1.0).contains(c)), "{rgb:?}");
    }
    for space in [None, Some(ColourSpace::Srgb)] {
        let mut opts = RenderOptions::fit(&doc(vec![below.clone(), above.clone()]), 500);
        opts.colour_space_override = space;
        let draw = |layers: Vec<GradientMesh>| {
            let mut out = vec![0u8; 4 * opts.width as usize * opts.height as usize];
            gradmesh::render::render_document_into(&doc(layers), &opts, &mut out).unwrap();
            out
        };
        let together = draw(vec![below.clone(), above.clone()]);
        let (alone, top) = (draw(vec![below.clone()]), draw(vec![above.clone()]));
        // Pixels within two of one the star shows (its outline's coverage may be below what
        // eight bits show).
        let (w, h) = (opts.width as i64, opts.height as i64);
        let near_top = |x: i64, y: i64| {
            (y - 2..=y + 2).any(|v| {
                (x - 2..=x + 2).any(|u| {
                    (0..w).contains(&u)
                        && (0..h).contains(&v)
                        && top[4 * (v * w + u) as usize + 3] > 0
                })
            })
        };
        let mut compared = 0;
        for (i, (t, a)) in together.chunks(4).zip(alone.chunks(4)).enumerate() {
            let (x, y) = (i as i64 % w, i as i64 / w);
            if !near_top(x, y) {
                assert_eq!(t, a, "{space:?}: pixel ({x}, {y})");
                compared += usize::from(a[3] == 255);
            }
        }
        // Most of the grid lies outside the star.
        assert!(compared > 50_000, "{space:?}: {compared}");
        // And the star does cover part of it.
        assert!(together != alone);
    }
}

/// Reference mode is converged: one more level changes no 16-bit channel by more than one step
/// inside the outline.
#[test]
fn reference_is_converged() {
    for (name, mesh) in test_meshes().into_iter().take(2) {
        let d = doc(vec![mesh]);
        let mut opts = RenderOptions::fit(&d, 96);
        opts.reference = true;
        let (a, info) = render_image(&d, &opts).unwrap();
        opts.level = Some(info.layers[0].level + 1);
        // The level above reference mode's may hold more quads than the default cap allows.
        opts.max_quads = 1 << 24;
        let b = render_document(&d, &opts).unwrap();
        let (qa, qb) = (a.to_u16(), b.to_u16());
        let mut worst = 0;
        for (x, y) in interior(&a, 1) {
            let i = 4 * (y as usize * a.width as usize + x as usize);
            for c in 0..4 {
                worst = worst.max((qa[i + c] as i32 - qb[i + c] as i32).abs());
            }
        }
        eprintln!(
            "{name}: reference level {} vs {}: largest 16-bit change {worst}",
            info.layers[0].level,
            info.layers[0].level + 1
        );
        assert!(worst <= 1, "{name}: {worst}");
    }
}

/// A discontinuous edge whose sides carry the same colours is invisible: the rendering equals that
/// of the same mesh with an infinitely sharp crease there (which refines identically, side by side).
#[test]
fn discontinuous_edge_without_colour_jump_has_no_seam() {
    let make = |kind: EdgeKind| {
        let mut mesh = grid(4, 3, [0.0, 0.0, 400.0, 300.0], 0.3, soft_colour);
        // The column of edges from top to bottom at i = 2, and a bend along row j = 1.
        let v = |i: u32, j: u32| j * 5 + i;
        for j in 0..3 {
            mesh.set_edge(v(2, j), v(2, j + 1), kind, None);
        }
        mesh
    };
    let cut = doc(vec![make(EdgeKind::Discontinuous)]);
    let crease = doc(vec![make(EdgeKind::Crease)]);
    let opts = RenderOptions::fit(&cut, 256);
    let a = render_document(&cut, &opts).unwrap();
    let b = render_document(&crease, &opts).unwrap();
    save("seam-cut", &a);
    save("seam-crease", &b);
    let mut worst = 0.0f32;
    for (x, y) in a.data.iter().zip(&b.data) {
        worst = worst.max((x - y).abs());
    }
    eprintln!("cut vs crease: largest channel difference {worst:e}");
    assert!(worst <= 1.0 / 255.0, "{worst}");
    // And the cut is fully covered: no pixel inside shows any transparency.
    for (x, y) in interior(&b, 2) {
        assert_eq!(a.pixel(x, y)[3], 1.0, "({x}, {y})");
    }
}

/// Over an opaque background, no interior edge lets the background through: every pixel whose
/// square lies inside the mesh is exactly opaque, including along a discontinuous edge with
/// different colours on its two sides.
#[test]
fn no_background_along_interior_edges() {
    let rect = [10.3, 12.7, 200.6, 150.2];
    let mut mesh = grid(5, 4, rect, 0.0, soft_colour);
    let v = |i: u32, j: u32| j * 6 + i;
    for j in 0..4 {
        mesh.set_edge(v(3, j), v(3, j + 1), EdgeKind::Discontinuous, None);
    }
    // The right side of the cut is dark blue.
    for j in 0..=4 {
        let face = j.min(3) * 5 + 3;
        mesh.wedges.push(WedgeOverride {
            point: v(3, j),
            face,
            colour: [25.0, 10.0, -40.0],
            colour_text: None,
            opacity: None,
            handles: BTreeMap::new(),
        });
    }
    let d = doc(vec![mesh]);
    let mut opts = RenderOptions::new(211, 163, View::new(0.0, 0.0, 211.0, 163.0));
    let plain = render_document(&d, &opts).unwrap();
    opts.background = Some([1.0, 0.0, 1.0, 1.0]);
    let over = render_document(&d, &opts).unwrap();
    save("background-cut", &over);
    let mut inside = 0;
    for y in 0..opts.height {
        for x in 0..opts.width {
            let (px, py) = (x as f64, y as f64);
            if px >= rect[0] && px + 1.0 <= rect[2] && py >= rect[1] && py + 1.0 <= rect[3] {
                inside += 1;
                assert_eq!(plain.pixel(x, y)[3], 1.0, "({x}, {y}) not opaque");
                assert_eq!(over.pixel(x, y), plain.pixel(x, y), "({x}, {y})");
            }
        }
    }
    assert!(inside > 20_000);
    // The two sides really differ (so the cut is there).
    let (l, r) = (plain.pixel(100, 80), plain.pixel(140, 80));
    assert!(delta_e(l, r) > 10.0);
}

/// Area of the part of pixel (i, j) inside a convex polygon (Sutherland-Hodgman, shoelace).
fn exact_coverage(poly: &[[f64; 2]], i: u32, j: u32) -> f64 {
    let mut poly = poly.to_vec();
    let (x0, y0) = (i as f64, j as f64);
    for (axis, v, sign) in [
        (0, x0, 1.0),
        (0, x0 + 1.0, -1.0),
        (1, y0, 1.0),
        (1, y0 + 1.0, -1.0),
    ] {
        let inside = |p: &[f64; 2]| (p[axis] - v) * sign >= 0.0;
        let mut out = Vec::new();
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let t = (v - a[axis]) / (b[axis] - a[axis]);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        poly = out;
        if poly.is_empty() {
            return 0.0;
        }
    }
    let mut area = 0.0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        area += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * area.abs()
}

/// Anti-aliasing is exact area coverage: a rotated rectangle grid with default handles has a
/// straight outline through its corner points.
#[test]
fn outline_coverage_is_exact_area() {
    for angle in [0.0, 0.35, 1.1] {
        let rect = [20.25, 30.5, 170.0, 120.75];
        let mesh = grid(3, 2, rect, angle, soft_colour);
        let corners: Vec<[f64; 2]> = [0, 3, 11, 8]
            .iter()
            .map(|&k| {
                let p = mesh.points[k].position;
                [p.x, p.y]
            })
            .collect();
        let d = doc(vec![mesh]);
        let opts = RenderOptions::new(192, 160, View::new(0.0, 0.0, 192.0, 160.0));
        let img = render_document(&d, &opts).unwrap();
        save(&format!("coverage-{angle}"), &img);
        let mut worst = 0.0f64;
        let mut partial = 0;
        for y in 0..opts.height {
            for x in 0..opts.width {
                let e = exact_coverage(&corners, x, y);
                if e > 0.0 && e < 1.0 {
                    partial += 1;
                }
                worst = worst.max((img.pixel(x, y)[3] as f64 - e).abs());
            }
        }
        eprintln!("angle {angle}: largest coverage error {worst:e} over {partial} edge pixels");
        assert!(partial > 100);
        assert!(worst <= 2.0 / 255.0, "angle {angle}: {worst}");
    }
}

/// A hole stays empty; the ring around it is opaque.
#[test]
fn holes_are_empty() {
    let d = doc(vec![annulus(Point::new(100.0, 100.0), 40.0, 90.0, 8)]);
    let opts = RenderOptions::new(200, 200, View::new(0.0, 0.0, 200.0, 200.0));
    let img = render_document(&d, &opts).unwrap();
    save("hole", &img);
    assert_eq!(img.pixel(100, 100)[3], 0.0);
    assert_eq!(img.pixel(80, 100)[3], 0.0);
    assert_eq!(img.pixel(100, 35)[3], 1.0);
    assert_eq!(img.pixel(35, 100)[3], 1.0);
}

/// The same bits with one thread as with several.
#[test]
fn deterministic_across_thread_counts() {
    let d = doc(vec![
        grid(4, 3, [0.0, 0.0, 400.0, 300.0], 0.2, soft_colour),
        star(Point::new(200.0, 150.0), 120.0),
    ]);
    let opts = RenderOptions::fit(&d, 300);
    let render = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render_document(&d, &opts).unwrap())
    };
    let one = render(1);
    save("layers", &one);
    assert_eq!(one, render(4));
    assert_eq!(one, render(3));
}

/// All three output types agree with the float image.
#[test]
fn output_types_agree() {
    let d = doc(vec![star(Point::new(0.0, 0.0), 50.0)]);
    let mut opts = RenderOptions::fit(&d, 64);
    opts.dither = false;
    let img = render_document(&d, &opts).unwrap();
    let mut b8 = vec![0u8; img.data.len()];
    let mut b16 = vec![0u16; img.data.len()];
    gradmesh::render::render_document_into(&d, &opts, &mut b8).unwrap();
    gradmesh::render::render_document_into(&d, &opts, &mut b16).unwrap();
    assert_eq!(b8, img.to_u8(false));
    assert_eq!(b16, img.to_u16());
    // Dithered as the float image would be (the 8-bit encoding saturates by itself: the
    // renderer does not clamp before it).
    opts.dither = true;
    gradmesh::render::render_document_into(&d, &opts, &mut b8).unwrap();
    assert_eq!(b8, img.to_u8(true));
    let mut wrong = vec![0u8; 5];
    assert!(gradmesh::render::render_document_into(&d, &opts, &mut wrong).is_err());
}

/// Rows below the drawing (bands no layer reaches, written as one encoded pixel) hold the
/// background, in every output type, as the float image's encodings of it.
#[test]
fn rows_without_layers_are_the_background() {
    let d = doc(vec![star(Point::new(30.0, 30.0), 25.0)]);
    for background in [
        None,
        Some([0.2, 0.45, 0.9, 0.6]),
        Some([1.0, 1.0, 1.0, 1.0]),
    ] {
        let mut opts = RenderOptions::new(60, 150, View::new(0.0, 0.0, 60.0, 150.0));
        opts.background = background;
        for dither in [false, true] {
            opts.dither = dither;
            let img = render_document(&d, &opts).unwrap();
            let bg = background.map_or([0.0f32; 4], |b| b.map(|v| v as f32));
            let bg = if bg[3] == 0.0 { [0.0; 4] } else { bg };
            // Below the star (rows 64 on are four bands of 16 that it does not reach).
            for y in 64..150 {
                for x in 0..60 {
                    let px = img.pixel(x, y);
                    for c in 0..4 {
                        assert!(
                            (px[c] - bg[c]).abs() < 1e-6,
                            "{background:?} ({x}, {y}): {px:?}"
                        );
                    }
                }
            }
            let mut b8 = vec![0u8; img.data.len()];
            let mut b16 = vec![0u16; img.data.len()];
            gradmesh::render::render_document_into(&d, &opts, &mut b8).unwrap();
            gradmesh::render::render_document_into(&d, &opts, &mut b16).unwrap();
            assert_eq!(b8, img.to_u8(dither), "{background:?} dither {dither}");
            assert_eq!(b16, img.to_u16(), "{background:?}");
        }
    }
}

/// A handle pointing backwards folds the surface; `find_folds` finds it, and nothing on a plain
/// grid.
#[test]
fn folds_are_found() {
    let plain = grid(2, 2, [0.0, 0.0, 200.0, 200.0], 0.0, soft_colour);
    assert!(find_folds(&plain).unwrap().is_empty());
    let mut folded = plain.clone();
    // The centre point (4) pulls its handle towards point 5 (to its right) far to the left.
    folded.set_handle(4, 5, Vec2::new(-90.0, 0.0));
    let folds = find_folds(&folded).unwrap();
    eprintln!("{folds:?}");
    assert!(!folds.is_empty());
    let f = &folds[0];
    assert!(f.area > 0.0);
    assert!(f.faces.iter().all(|&face| face < 4));
    assert!(f.bounds.contains(f.position) || f.bounds.area() == 0.0);
    let d = doc(vec![folded]);
    let img = render_document(&d, &RenderOptions::fit(&d, 200)).unwrap();
    save("fold", &img);
}

/// A layer at half opacity over an opaque background: source-over in sRGB-encoded values by
/// default, in linear light on request.
#[test]
fn opacity_composites_in_the_blend_space() {
    let red = ColourSpace::Srgb.convert(ColourSpace::Lab, [0.8, 0.2, 0.3]);
    let mut mesh = grid(2, 2, [0.0, 0.0, 100.0, 100.0], 0.0, |_, _| red);
    mesh.points.iter_mut().for_each(|p| p.opacity = 0.5);
    let d = doc(vec![mesh]);
    let mut opts = RenderOptions::new(100, 100, View::new(0.0, 0.0, 100.0, 100.0));
    opts.background = Some([0.1, 0.9, 0.5, 1.0]);
    let img = render_document(&d, &opts).unwrap();
    let px = img.pixel(50, 50);
    for (c, (v, bg)) in [0.8, 0.2, 0.3].iter().zip([0.1, 0.9, 0.5]).enumerate() {
        assert!((px[c] as f64 - (0.5 * v + 0.5 * bg)).abs() < 1e-4, "{px:?}");
    }
    assert_eq!(px[3], 1.0);
    opts.blend = BlendSpace::Linear;
    let img = render_document(&d, &opts).unwrap();
    let px = img.pixel(50, 50);
    let lin = |v: f64| ColourSpace::Srgb.to_linear_srgb([v, v, v])[0];
    let enc = |v: f64| ColourSpace::SrgbLinear.convert(ColourSpace::Srgb, [v, v, v])[0];
    for (c, (v, bg)) in [0.8, 0.2, 0.3].iter().zip([0.1, 0.9, 0.5]).enumerate() {
        let expect = enc(0.5 * lin(*v) + 0.5 * lin(bg));
        assert!((px[c] as f64 - expect).abs() < 1e-4, "{px:?}");
    }
    // Without background: straight alpha 0.5 and the layer's own colour.
    opts.background = None;
    let px = render_document(&d, &opts).unwrap().pixel(50, 50);
    assert!(
        (px[3] - 0.5).abs() < 1e-6 && (px[0] - 0.8).abs() < 1e-4,
        "{px:?}"
    );
}

/// Layers drawn together equal each layer drawn alone and composited back to front (source-over
/// in sRGB-encoded values), with partial opacity, anti-aliased edges, an opaque layer hiding part
/// of those below it, and a background under all.
#[test]
fn layers_composite_like_separate_images() {
    let star_layer = |c: Point, r: f64, opacity: f64| {
        let mut m = star(c, r);
        m.points.iter_mut().for_each(|p| p.opacity = opacity);
        m
    };
    let layers = vec![
        grid(3, 3, [5.0, 5.0, 95.0, 95.0], 0.3, soft_colour),
        star_layer(Point::new(40.0, 45.0), 35.0, 0.6),
        star_layer(Point::new(60.0, 55.0), 30.0, 1.0),
        star_layer(Point::new(50.0, 50.0), 20.0, 0.3),
    ];
    let mut opts = RenderOptions::new(120, 120, View::new(0.0, 0.0, 100.0, 100.0));
    let bg = [0.2, 0.4, 0.9, 0.7];
    opts.background = Some(bg);
    let together = render_document(&doc(layers.clone()), &opts).unwrap();
    opts.background = None;
    let alone: Vec<Image> = layers
        .iter()
        .map(|m| render_document(&doc(vec![m.clone()]), &opts).unwrap())
        .collect();
    let mut opaque_hidden = 0;
    for y in 0..120 {
        for x in 0..120 {
            // Premultiplied source-over, bottom first.
            let mut acc = [bg[0] * bg[3], bg[1] * bg[3], bg[2] * bg[3], bg[3]];
            for img in &alone {
                let p = img.pixel(x, y).map(|v| v as f64);
                for c in 0..3 {
                    acc[c] = p[c] * p[3] + acc[c] * (1.0 - p[3]);
                }
                acc[3] = p[3] + acc[3] * (1.0 - p[3]);
            }
            if alone[2].pixel(x, y)[3] == 1.0 && alone[1].pixel(x, y)[3] > 0.0 {
                opaque_hidden += 1;
            }
            let got = together.pixel(x, y);
            assert!((got[3] as f64 - acc[3]).abs() < 1e-5, "({x}, {y}): {got:?}");
            for c in 0..3 {
                let expect = acc[c] / acc[3];
                assert!(
                    (got[c] as f64 - expect).abs() < 1e-4,
                    "({x}, {y}): {got:?} against {expect}"
                );
            }
        }
    }
    assert!(opaque_hidden > 500, "{opaque_hidden}");
}

/// Interpolating in another space changes the colours between control points, not at them.
#[test]
fn colour_space_override_and_gamut_options() {
    let (a, b) = ([60.0, 70.0, 50.0], [60.0, -60.0, -40.0]);
    let mesh = grid(1, 1, [0.0, 0.0, 100.0, 20.0], 0.0, |i, _| {
        if i == 0 {
            a
        } else {
            b
        }
    });
    let d = doc(vec![mesh]);
    let mut opts = RenderOptions::new(100, 20, View::new(0.0, 0.0, 100.0, 20.0));
    let lab = render_document(&d, &opts).unwrap();
    opts.colour_space_override = Some(ColourSpace::Srgb);
    let srgb = render_document(&d, &opts).unwrap();
    assert!(delta_e(lab.pixel(50, 10), srgb.pixel(50, 10)) > 2.0);
    assert!(delta_e(lab.pixel(0, 10), srgb.pixel(0, 10)) < 0.5);
    // This Lab blend leaves the sRGB gamut: clipping and chroma reduction differ there.
    opts.colour_space_override = None;
    opts.gamut = GamutMapping::Clip;
    let clipped = render_document(&d, &opts).unwrap();
    let differing = (0..100)
        .filter(|&x| clipped.pixel(x, 10) != lab.pixel(x, 10))
        .count();
    assert!(differing > 0);
    save("override-lab", &lab);
    save("override-srgb", &srgb);
}

/// The outline overlay darkens the pixels on the outline and nothing far from it.
#[test]
fn outlines_are_drawn_on_top() {
    let d = doc(vec![star(Point::new(100.0, 100.0), 90.0)]);
    let opts = RenderOptions::new(200, 200, View::new(0.0, 0.0, 200.0, 200.0));
    let plain = render_document(&d, &opts).unwrap();
    let mut lined = plain.clone();
    draw_outlines(&d, &opts, &mut lined).unwrap();
    save("outline", &lined);
    assert_eq!(plain.pixel(100, 100), lined.pixel(100, 100));
    assert_eq!(plain.pixel(2, 2), lined.pixel(2, 2));
    let changed = (0..200 * 200)
        .filter(|&k| plain.pixel(k % 200, k / 200) != lined.pixel(k % 200, k / 200))
        .count();
    // About one pixel along an outline of some 900 pixels' length.
    assert!((600..3000).contains(&changed), "{changed}");
}

/// The authors' artwork (extended OFF): Condition 1 at the in-gamut control points, and the fast
/// path against the reference.
///
/// Condition 1 holds at the limit point itself, and the colour is flat around it over a region
/// as wide as the point's handles; a pixel centre lies up to 0.7 pixel away, so the image must be
/// large enough that the shortest handles (under a unit in this artwork) span a pixel or so.
#[test]
fn real_artwork() {
    for name in [
        "Paprika_Paprika_layer0",
        "Tucan_Tucan_Layer3",
        "Tucan_Tucan_Layer1",
    ] {
        let text = std::fs::read_to_string(realdata::path(&format!("{name}.off"))).unwrap();
        let mesh = gradmesh::formats::off::read_off(&text).unwrap();
        let d = doc(vec![mesh.clone()]);

        let opts = RenderOptions::fit(&d, 1024);
        let img = render_document(&d, &opts).unwrap();
        save(&format!("real-{name}"), &img);
        let mut worst = 0.0f64;
        for (p, colour) in limit_points(&mesh) {
            if !ColourSpace::Lab.in_srgb_gamut(colour) {
                continue;
            }
            let (x, y) = to_pixel(&opts, p);
            let px = img.pixel(x, y);
            let got = ColourSpace::Srgb
                .convert(ColourSpace::Lab, [px[0] as f64, px[1] as f64, px[2] as f64]);
            worst = worst.max(lab(got).difference(lab(colour)));
        }
        eprintln!("{name}: worst dE00 at in-gamut control points {worst:.4}");
        assert!(worst <= 0.5, "{name}: {worst}");

        let mut opts = RenderOptions::fit(&d, 128);
        let fast = render_document(&d, &opts).unwrap();
        opts.reference = true;
        let reference = render_document(&d, &opts).unwrap();
        let pixels = interior(&reference, 2);
        let (mut max, mut sum) = (0.0f64, 0.0);
        for &(x, y) in &pixels {
            let e = delta_e(fast.pixel(x, y), reference.pixel(x, y));
            max = max.max(e);
            sum += e;
        }
        let mean = sum / pixels.len() as f64;
        eprintln!("{name}: fast vs reference max dE00 {max:.4}, mean {mean:.5}");
        assert!(max <= 0.5 && mean <= 0.05, "{name}: {max} {mean}");
    }
}
