//! `RenderCache`: renders that reuse prepared layers are identical to renders from scratch, and
//! only the layers that changed (or all, when an option that shapes preparation changed) are
//! prepared again, each planning again only the faces an edit touched.

use gradmesh::formats::read_path;
use gradmesh::render::BlendSpace;
use gradmesh::render::{
    document_bounds, render_document_into, render_document_into_cached, RenderCache, RenderOptions,
    View,
};
use gradmesh::{ColourSpace, Document, GradientMesh};
use kurbo::Point;

use crate::realdata;

/// The six layers of the authors' Tucan, bottom to top.
fn tucan() -> Document {
    let layers = (0..6)
        .rev()
        .map(|i| {
            let path = realdata::path(&format!("Tucan_Tucan_Layer{i}.off"));
            let mut doc = read_path(&path).unwrap();
            doc.layers.remove(0)
        })
        .collect();
    Document::new(layers)
}

fn options(doc: &Document, width: u32) -> RenderOptions {
    let b = document_bounds(doc).unwrap();
    let height = (width as f64 * b.height() / b.width()).ceil() as u32;
    RenderOptions::new(width, height, View::new(b.x0, b.y0, b.x1, b.y1))
}

/// Renders with the cache and from scratch; asserts the pixels agree and returns which layers
/// were reused.
fn render_both(doc: &Document, opts: &RenderOptions, cache: &mut RenderCache) -> Vec<bool> {
    render_both_counting(doc, opts, cache).0
}

/// [`render_both`], and how many faces of each layer kept their plans.
fn render_both_counting(
    doc: &Document,
    opts: &RenderOptions,
    cache: &mut RenderCache,
) -> (Vec<bool>, Vec<usize>) {
    let n = 4 * (opts.width * opts.height) as usize;
    let (mut cached, mut fresh) = (vec![0u8; n], vec![0u8; n]);
    let info = render_document_into_cached(doc, opts, cache, &mut cached).unwrap();
    let plain = render_document_into(doc, opts, &mut fresh).unwrap();
    assert!(cached == fresh, "cached and fresh renders differ");
    assert!(plain.layers.iter().all(|l| !l.reused));
    for (a, b) in info.layers.iter().zip(&plain.layers) {
        // Everything but the timings is what preparing again gives.
        assert_eq!(
            (a.level, a.quads, a.triangles),
            (b.level, b.quads, b.triangles)
        );
    }
    assert_eq!(info.warnings, plain.warnings);
    assert!(plain.layers.iter().all(|l| l.reused_faces == 0));
    (
        info.layers.iter().map(|l| l.reused).collect(),
        info.layers.iter().map(|l| l.reused_faces).collect(),
    )
}

#[test]
fn cached_renders_equal_fresh_ones_and_prepare_only_what_changed() {
    let mut doc = tucan();
    let mut opts = options(&doc, 300);
    let mut cache = RenderCache::new();

    assert_eq!(render_both_counting(&doc, &opts, &mut cache).1, [0; 6]);
    assert_eq!(
        render_both_counting(&doc, &opts, &mut cache),
        (vec![true; 6], vec![0; 6])
    );

    // An edit of one layer: only that one is prepared again, and only the faces near the
    // point are planned again (the cache keeps every face's plan from the first render on).
    let p = &mut doc.layers[3].points[5];
    p.colour = [p.colour[0] * 0.8, p.colour[1] + 10.0, p.colour[2]];
    let (reused, faces) = render_both_counting(&doc, &opts, &mut cache);
    assert_eq!(reused, [true, true, true, false, true, true]);
    assert!(faces[3] > 0, "no face kept its plan: {faces:?}");
    assert_eq!(faces.iter().filter(|&&f| f > 0).count(), 1);
    let p = &mut doc.layers[3].points[5];
    p.colour[2] -= 5.0;
    let (reused, faces) = render_both_counting(&doc, &opts, &mut cache);
    assert_eq!(reused, [true, true, true, false, true, true]);
    assert!(faces[3] > 0, "no face kept its plan: {faces:?}");

    // A point moved, and moved back: its layer is prepared again, reusing the local
    // refinements kept for its topology, and the second time the plans of the faces far from
    // the point (the pixels are checked against a render from scratch).
    let p = &mut doc.layers[2].points[7];
    p.position.x += 3.0;
    p.position.y -= 2.0;
    assert_eq!(
        render_both(&doc, &opts, &mut cache),
        [true, true, false, true, true, true]
    );
    let p = &mut doc.layers[2].points[7];
    p.position.x -= 3.0;
    p.position.y += 2.0;
    let (reused, faces) = render_both_counting(&doc, &opts, &mut cache);
    assert_eq!(reused, [true, true, false, true, true, true]);
    assert!(faces[2] > 0, "no face kept its plan: {faces:?}");

    // Drawing-only options keep every layer.
    opts.background = Some([1.0, 1.0, 1.0, 1.0]);
    opts.dither = false;
    assert_eq!(render_both(&doc, &opts, &mut cache), [true; 6]);

    // A new size prepares everything again.
    opts.width = 320;
    opts.height += 10;
    assert_eq!(render_both(&doc, &opts, &mut cache), [false; 6]);

    // A layer removed from the top, then one added: positions that still match are kept.
    let top = doc.layers.pop().unwrap();
    assert_eq!(render_both(&doc, &opts, &mut cache), [true; 5]);
    doc.layers.push(top);
    assert_eq!(
        render_both(&doc, &opts, &mut cache),
        [true, true, true, true, true, false]
    );
}

/// Renders with the cache into `P` pixels and from scratch, asserts they agree, and returns
/// how many bands the cached render drew.
fn drawn_bands<P: gradmesh::render::OutputPixel + Default + PartialEq + std::fmt::Debug>(
    doc: &Document,
    opts: &RenderOptions,
    cache: &mut RenderCache,
) -> usize {
    drawn::<P>(doc, opts, cache).0
}

/// [`drawn_bands`], and how many pixels the cached render drew.
fn drawn<P: gradmesh::render::OutputPixel + Default + PartialEq + std::fmt::Debug>(
    doc: &Document,
    opts: &RenderOptions,
    cache: &mut RenderCache,
) -> (usize, u64) {
    let n = 4 * (opts.width * opts.height) as usize;
    let (mut cached, mut fresh) = (vec![P::default(); n], vec![P::default(); n]);
    let info = render_document_into_cached(doc, opts, cache, &mut cached).unwrap();
    render_document_into(doc, opts, &mut fresh).unwrap();
    assert!(cached == fresh, "cached and fresh renders differ");
    // Bit for bit: `==` takes -0 for 0.
    let bits = |v: &[P]| format!("{v:?}");
    if std::any::TypeId::of::<P>() == std::any::TypeId::of::<f32>() {
        assert!(
            bits(&cached) == bits(&fresh),
            "cached and fresh renders differ"
        );
    }
    (info.drawn_bands, info.drawn_pixels)
}

#[test]
fn edits_draw_again_only_the_bands_they_change() {
    let mut doc = tucan();
    let opts = options(&doc, 300);
    let all = (opts.height as usize).div_ceil(16);
    let mut cache = RenderCache::new();
    assert_eq!(drawn_bands::<u8>(&doc, &opts, &mut cache), all);
    assert_eq!(drawn_bands::<u8>(&doc, &opts, &mut cache), 0);

    // Points moved and recoloured in every layer, inside and on the outline; each cached
    // render equals one from scratch (into a buffer that held nothing), and some edits draw
    // only part of the image.
    let mut partial = 0;
    for l in 0..doc.layers.len() {
        let count = doc.layers[l].points.len();
        for k in [0, count / 3, count / 2, count - 1] {
            let p = &mut doc.layers[l].points[k];
            p.position.x += 0.7;
            p.position.y -= 0.4;
            let moved = drawn_bands::<u8>(&doc, &opts, &mut cache);
            let p = &mut doc.layers[l].points[k];
            p.colour[1] += 6.0;
            let recoloured = drawn_bands::<u8>(&doc, &opts, &mut cache);
            for n in [moved, recoloured] {
                assert!(n > 0, "layer {l} point {k}: nothing drawn again");
                partial += usize::from(n < all);
            }
        }
    }
    assert!(partial >= 8, "only {partial} edits drew part of the image");

    // Another pixel type, then back: every band the first time, then only what changed.
    assert_eq!(drawn_bands::<f32>(&doc, &opts, &mut cache), all);
    assert_eq!(drawn_bands::<f32>(&doc, &opts, &mut cache), 0);
    assert_eq!(drawn_bands::<u8>(&doc, &opts, &mut cache), all);

    // A drawing option draws everything again, the layers being kept.
    let mut opts = opts;
    opts.dither = !opts.dither;
    assert_eq!(drawn_bands::<u8>(&doc, &opts, &mut cache), all);
    assert_eq!(drawn_bands::<u8>(&doc, &opts, &mut cache), 0);
}

/// Within the bands an edit changes, only the columns it can change are drawn again, and the
/// pixels are those of a render from scratch: in every kind of output (dithered, linear
/// blending, on a background, 16-bit, float) and working space (Lab's runs, an sRGB layer's
/// own loop, the gamut search of colours out of range).
#[test]
fn edits_draw_again_only_the_columns_they_change() {
    let mut doc = tucan();
    // Layer 4 in sRGB with every colour in range, layer 1 in Oklab (some of its colours are
    // outside sRGB).
    let mut convert = |l: usize, space: ColourSpace, clamp: bool| {
        let layer = &mut doc.layers[l];
        let colours = layer.points.iter_mut().map(|p| &mut p.colour);
        for c in colours.chain(layer.wedges.iter_mut().map(|w| &mut w.colour)) {
            *c = layer.colour_space.convert(space, *c);
            if clamp {
                *c = c.map(|v| v.clamp(0.0, 1.0));
            }
        }
        layer.colour_space = space;
    };
    convert(4, ColourSpace::Srgb, true);
    convert(1, ColourSpace::Oklab, false);
    let base = options(&doc, 300);
    let band_pixels = |bands: usize| (bands * 16 * base.width as usize) as u64;
    let mut kinds = Vec::new();
    for (dither, blend, background) in [
        (true, BlendSpace::Srgb, None),
        (false, BlendSpace::Linear, Some([0.9, 0.8, 0.7, 0.6])),
    ] {
        let mut opts = base.clone();
        (opts.dither, opts.blend, opts.background) = (dither, blend, background);
        kinds.push(opts);
    }
    for (k, opts) in kinds.iter().enumerate() {
        let mut doc = doc.clone();
        // The second kind in 16-bit and float pixels, each with its own cache.
        let mut caches = [RenderCache::new(), RenderCache::new()];
        let mut draw = |doc: &Document| match k {
            0 => drawn::<u8>(doc, opts, &mut caches[0]),
            _ => {
                let (bands, pixels) = drawn::<u16>(doc, opts, &mut caches[0]);
                assert_eq!(drawn::<f32>(doc, opts, &mut caches[1]), (bands, pixels));
                (bands, pixels)
            }
        };
        draw(&doc);
        let (mut fewer, mut edits) = (0, 0);
        for l in [1, 3, 4, 5] {
            let count = doc.layers[l].points.len();
            for i in [0, count / 2, count - 1] {
                for step in [0.6, -0.6] {
                    let p = &mut doc.layers[l].points[i];
                    p.position.x += step;
                    p.position.y -= 0.5 * step;
                    let (bands, pixels) = draw(&doc);
                    assert!(pixels <= band_pixels(bands));
                    assert!(bands == 0 || pixels > 0);
                    fewer += usize::from(pixels < band_pixels(bands) / 2);
                    edits += 1;
                }
            }
        }
        assert!(
            3 * fewer >= 2 * edits,
            "only {fewer} of {edits} edits drew under half their bands' columns"
        );
    }
}

/// A change of a layer's outline draws again the columns around the lines that changed, not
/// the rest of the rows to the layer's right end: coverage sums are exact, so past the change
/// they are the same. A boundary point on the left side of a wide grid moves; the pixels drawn
/// again are a small part of the bands they lie in, and the same as a render from scratch, in
/// 8-bit and float pixels.
#[test]
fn an_outline_change_draws_again_only_around_it() {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    let (columns, rows, cell) = (16u32, 2u32, 10.0);
    for j in 0..=rows {
        for i in 0..=columns {
            let colour = [40.0 + 2.5 * i as f64, 10.0 * j as f64, -20.0];
            mesh.add_point(Point::new(cell * i as f64, cell * j as f64), colour);
        }
    }
    for j in 0..rows {
        for i in 0..columns {
            let v = j * (columns + 1) + i;
            mesh.add_face(vec![v, v + 1, v + columns + 2, v + columns + 1]);
        }
    }
    let mut doc = Document::new(vec![mesh]);
    let opts = options(&doc, 400);
    let band_pixels = |bands: usize| (bands * 16 * opts.width as usize) as u64;
    let left_middle = (columns + 1) as usize;
    for pixels_kind in 0..2 {
        let mut cache = RenderCache::new();
        let mut draw = |doc: &Document| match pixels_kind {
            0 => drawn::<u8>(doc, &opts, &mut cache),
            _ => drawn::<f32>(doc, &opts, &mut cache),
        };
        draw(&doc);
        for step in [-0.3, 0.3] {
            doc.layers[0].points[left_middle].position.x += step;
            let (bands, pixels) = draw(&doc);
            assert!(bands > 0 && pixels > 0, "nothing drawn again");
            assert!(
                3 * pixels < band_pixels(bands),
                "{pixels} pixels drawn again in {bands} bands of {} pixels",
                opts.width
            );
        }
    }
}

#[test]
fn a_draft_keeps_the_last_counts_evaluates_only_what_an_edit_reaches_and_the_next_render_is_exact()
{
    let mut doc = tucan();
    let exact = options(&doc, 600);
    let draft = RenderOptions {
        draft: true,
        ..exact.clone()
    };
    let mut cache = RenderCache::new();
    render_both(&doc, &exact, &mut cache);
    let n = 4 * (exact.width * exact.height) as usize;
    let mut pixels = vec![0u8; n];
    let before = render_document_into_cached(&doc, &exact, &mut cache, &mut pixels).unwrap();

    // Nothing changed: a draft plans nothing, and draws what the exact render drew.
    let info = render_document_into_cached(&doc, &draft, &mut cache, &mut pixels).unwrap();
    assert!(info.layers.iter().all(|l| l.reused));
    let mut fresh = vec![0u8; n];
    render_document_into(&doc, &exact, &mut fresh).unwrap();
    assert!(pixels == fresh, "a draft of an unchanged document differs");

    // A point dragged in steps: each draft keeps the counts of the render before the drag
    // (the same cells), evaluates the faces near the point on the moved points, keeps the
    // others' plans, and leaves the other layers alone; its picture is within a few levels of
    // the exact render of the same points.
    for step in 1..=4 {
        let p = &mut doc.layers[2].points[7];
        p.position.x += 1.5;
        p.position.y -= 1.0;
        let drafted = render_document_into_cached(&doc, &draft, &mut cache, &mut pixels).unwrap();
        render_document_into(&doc, &exact, &mut fresh).unwrap();
        let reused: Vec<bool> = drafted.layers.iter().map(|l| l.reused).collect();
        assert_eq!(reused, [true, true, false, true, true, true]);
        let layer = &drafted.layers[2];
        assert!(layer.reused_faces > 0, "no face kept its plan");
        assert_eq!(
            layer.quads, before.layers[2].quads,
            "step {step}: counts changed"
        );
        let worst = (pixels.iter().zip(&fresh))
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap();
        assert!(
            worst <= 3,
            "step {step}: a draft's channel {worst} levels from the exact render"
        );
    }

    // The draft drew the moved point: away from the exact picture of the unmoved one.
    let mut unmoved = doc.clone();
    let p = &mut unmoved.layers[2].points[7];
    p.position.x -= 6.0;
    p.position.y += 4.0;
    let mut still = vec![0u8; n];
    render_document_into(&unmoved, &exact, &mut still).unwrap();
    let moved = |a: &[u8]| {
        a.iter()
            .zip(&still)
            .filter(|(x, y)| x.abs_diff(**y) > 8)
            .count()
    };
    assert!(moved(&pixels) > moved(&fresh) / 2, "the draft did not move");

    // The next render without `draft` plans the drafted faces again: the exact picture, with
    // only the drafted layer prepared again; after it nothing is left to plan.
    assert_eq!(
        render_both(&doc, &exact, &mut cache),
        [true, true, false, true, true, true]
    );
    assert_eq!(render_both(&doc, &exact, &mut cache), [true; 6]);
}
