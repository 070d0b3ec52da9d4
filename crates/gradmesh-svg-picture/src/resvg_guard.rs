//! Calls into resvg, guarded: a panic inside resvg or usvg is caught and becomes an error, and
//! the buffers a parsed tree would allocate are checked against the pixel and memory limits
//! before it is drawn.
//!
//! resvg allocates a layer for every isolated group (opacity, clip, mask, filter, blend), sized
//! to the group's layer bounds clipped to five times the canvas each way (a filter region is
//! part of those bounds), a tile for every pattern at its drawn size, and the results of a
//! filter's primitives at the layer's size. [`check_tree`] walks the tree as resvg draws it and
//! refuses a layer, a pattern tile or a filter over `max_pixels`, a morphology filter whose
//! work (pixels times window) is over [`MAX_MORPHOLOGY_READS`], and returns the peak of the
//! layers alive at once, in bytes.

use std::panic::{self, AssertUnwindSafe};
use std::sync::Mutex;

use resvg::usvg;

/// The most pixel reads a morphology filter may take (its layer's pixels times its window),
/// about a second: resvg's morphology visits the whole window for every pixel.
pub const MAX_MORPHOLOGY_READS: u64 = 2_000_000_000;

/// Bytes per pixel of resvg's premultiplied RGBA8 buffers.
const RESVG_BYTES_PER_PIXEL: u64 = 4;

/// Runs `f`, turning a panic into `Err` with the panic's message and place. The panic hook is
/// replaced while `f` runs, so the panic is reported once, by the caller.
pub fn catching<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    static MESSAGE: Mutex<Option<String>> = Mutex::new(None);
    let previous = panic::take_hook();
    panic::set_hook(Box::new(|info| {
        let payload = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".into());
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        *MESSAGE.lock().unwrap_or_else(|e| e.into_inner()) = Some(format!("{payload}{place}"));
    }));
    let result = panic::catch_unwind(AssertUnwindSafe(f));
    panic::set_hook(previous);
    result.map_err(|_| {
        MESSAGE
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
            .unwrap_or_else(|| "no message".into())
    })
}

/// What a tree was refused for.
#[derive(Debug, PartialEq)]
pub struct OverLimit {
    /// What is too large, naming the element.
    pub what: String,
    /// How large it is.
    pub found: u64,
    /// The limit.
    pub limit: u64,
}

/// The limits a tree is checked against, for a canvas of `width` x `height` pixels.
pub struct Canvas {
    /// The canvas's width in pixels.
    pub width: u32,
    /// The canvas's height in pixels.
    pub height: u32,
    /// The most pixels of any one buffer.
    pub max_pixels: u64,
}

impl Canvas {
    /// The pixels of the part of `rect` (canvas units) that resvg keeps: it clips layers to
    /// the canvas grown by twice its size on every side.
    fn clipped_pixels(&self, rect: usvg::Rect) -> u64 {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let x0 = f64::from(rect.left()).floor().max(-2.0 * w);
        let y0 = f64::from(rect.top()).floor().max(-2.0 * h);
        let x1 = f64::from(rect.right()).ceil().min(3.0 * w);
        let y1 = f64::from(rect.bottom()).ceil().min(3.0 * h);
        if !(x1 > x0 && y1 > y0) {
            return 0;
        }
        ((x1 - x0) * (y1 - y0)).min(u64::MAX as f64) as u64
    }

    fn check_pixels(&self, what: impl FnOnce() -> String, pixels: u64) -> Result<(), OverLimit> {
        if pixels > self.max_pixels {
            return Err(OverLimit {
                what: format!("{} (see --max-pixels)", what()),
                found: pixels,
                limit: self.max_pixels,
            });
        }
        Ok(())
    }
}

/// Checks every buffer resvg would allocate to draw `tree` on `canvas`; the peak bytes of the
/// buffers alive at once, beyond the canvas itself.
pub fn check_tree(tree: &usvg::Tree, canvas: &Canvas) -> Result<u64, OverLimit> {
    group_peak(tree.root(), canvas)
}

/// The element's name in messages.
fn named(kind: &str, id: &str) -> String {
    if id.is_empty() {
        format!("a {kind}")
    } else {
        format!("the {kind} id=\"{id}\"")
    }
}

/// The peak bytes of the layers drawing `group`'s children needs (its own layer excluded).
fn group_peak(group: &usvg::Group, canvas: &Canvas) -> Result<u64, OverLimit> {
    let mut peak = 0u64;
    for node in group.children() {
        let mut node_peak = match node {
            usvg::Node::Group(child) => isolated_peak(child, canvas)?,
            usvg::Node::Path(path) => pattern_peak(path, canvas)?,
            usvg::Node::Image(image) => image_peak(image, canvas)?,
            usvg::Node::Text(text) => group_peak(text.flattened(), canvas)?,
        };
        let mut subroots = Ok(0u64);
        node.subroots(|root| {
            if let Ok(bytes) = &mut subroots {
                match group_peak(root, canvas) {
                    Ok(b) => *bytes = (*bytes).max(b),
                    Err(e) => subroots = Err(e),
                }
            }
        });
        node_peak = node_peak.max(subroots?);
        peak = peak.max(node_peak);
    }
    Ok(peak)
}

/// The bytes of an image: an SVG image is drawn into a buffer of the canvas's size, a raster
/// image is decoded at its own size.
fn image_peak(image: &usvg::Image, canvas: &Canvas) -> Result<u64, OverLimit> {
    let what = || format!("the pixels of {}", named("image", image.id()));
    match image.kind() {
        usvg::ImageKind::SVG(tree) => {
            let pixels = u64::from(canvas.width) * u64::from(canvas.height);
            Ok(pixels * RESVG_BYTES_PER_PIXEL + group_peak(tree.root(), canvas)?)
        }
        _ => {
            let size = image.size();
            let pixels = (f64::from(size.width()).ceil() * f64::from(size.height()).ceil())
                .min(u64::MAX as f64) as u64;
            canvas.check_pixels(what, pixels)?;
            Ok(pixels * RESVG_BYTES_PER_PIXEL)
        }
    }
}

/// The peak bytes of a group: its own layer, when resvg isolates it, with what its filters,
/// clip and mask need, plus the peak of its children.
fn isolated_peak(group: &usvg::Group, canvas: &Canvas) -> Result<u64, OverLimit> {
    let inner = group_peak(group, canvas)?;
    if !group.should_isolate() {
        return Ok(inner);
    }
    // A filtered group's layer is its filters' region.
    let pixels = canvas.clipped_pixels(group.abs_layer_bounding_box().to_rect());
    let what = || match group.filters().first() {
        Some(filter) => format!("the region of {}", named("filter", filter.id())),
        None => format!("the layer of {}", named("group", group.id())),
    };
    canvas.check_pixels(what, pixels)?;
    // The layer, and a clip or mask buffer of its size.
    let mut buffers =
        1 + u64::from(group.clip_path().is_some()) + u64::from(group.mask().is_some());
    for filter in group.filters() {
        check_morphology(filter, group, pixels)?;
        // Each primitive's result is kept, with a source copy and a working buffer.
        buffers = buffers.max(1 + filter.primitives().len() as u64 + 2);
    }
    let own = pixels.saturating_mul(buffers * RESVG_BYTES_PER_PIXEL);
    Ok(own.saturating_add(inner))
}

/// Refuses a morphology primitive of `filter` whose work is over [`MAX_MORPHOLOGY_READS`].
fn check_morphology(
    filter: &usvg::filter::Filter,
    group: &usvg::Group,
    pixels: u64,
) -> Result<(), OverLimit> {
    let (sx, sy) = group.abs_transform().get_scale();
    let side = (pixels as f64).sqrt();
    for primitive in filter.primitives() {
        if let usvg::filter::Kind::Morphology(m) = primitive.kind() {
            // resvg clamps the radius to the layer's size.
            let rx = (f64::from(m.radius_x().get()) * f64::from(sx))
                .round()
                .min(side);
            let ry = (f64::from(m.radius_y().get()) * f64::from(sy))
                .round()
                .min(side);
            let reads = pixels as f64 * (2.0 * rx + 1.0) * (2.0 * ry + 1.0);
            if reads > MAX_MORPHOLOGY_READS as f64 {
                return Err(OverLimit {
                    what: format!(
                        "the pixel reads of the feMorphology in {} (radius {} x {} pixels over {} pixels)",
                        named("filter", filter.id()),
                        rx,
                        ry,
                        pixels
                    ),
                    found: reads.min(u64::MAX as f64) as u64,
                    limit: MAX_MORPHOLOGY_READS,
                });
            }
        }
    }
    Ok(())
}

/// The bytes of the pattern tiles a path's fill and stroke are drawn with.
fn pattern_peak(path: &usvg::Path, canvas: &Canvas) -> Result<u64, OverLimit> {
    let paints = [
        path.fill().map(|f| f.paint()),
        path.stroke().map(|s| s.paint()),
    ];
    let mut peak = 0u64;
    for paint in paints.into_iter().flatten() {
        if let usvg::Paint::Pattern(pattern) = paint {
            let (sx, sy) = path
                .abs_transform()
                .pre_concat(pattern.transform())
                .get_scale();
            let rect = pattern.rect();
            let tile = (f64::from(rect.width() * sx).round()
                * f64::from(rect.height() * sy).round())
            .min(u64::MAX as f64) as u64;
            canvas.check_pixels(
                || format!("the tile of {}", named("pattern", pattern.id())),
                tile,
            )?;
            let inner = group_peak(pattern.root(), canvas)?;
            peak = peak.max(tile * RESVG_BYTES_PER_PIXEL + inner);
        }
    }
    Ok(peak)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_an_error_with_its_message() {
        let caught = catching(|| -> u32 { panic!("inside resvg") });
        let message = caught.unwrap_err();
        assert!(message.starts_with("inside resvg at "), "{message}");
        assert!(message.contains("resvg_guard.rs"), "{message}");
        assert_eq!(catching(|| 7), Ok(7));
    }

    fn tree(text: &str) -> usvg::Tree {
        usvg::Tree::from_str(text, &usvg::Options::default()).unwrap()
    }

    fn canvas(max_pixels: u64) -> Canvas {
        Canvas {
            width: 100,
            height: 100,
            max_pixels,
        }
    }

    #[test]
    fn a_filter_region_over_the_pixel_limit_is_refused() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
            <filter id="f" filterUnits="userSpaceOnUse" x="-50" y="0" width="200" height="100">
              <feFlood flood-color="red"/></filter>
            <rect width="10" height="10" filter="url(#f)"/></svg>"#;
        let t = tree(svg);
        // 200 x 100 pixels of region.
        let err = check_tree(&t, &canvas(19_999)).unwrap_err();
        assert!(err.what.contains("id=\"f\""), "{err:?}");
        assert_eq!((err.found, err.limit), (20_000, 19_999));
        let bytes = check_tree(&t, &canvas(20_000)).unwrap();
        assert!(bytes >= 20_000 * 4 * 3, "{bytes}");
    }

    #[test]
    fn a_huge_region_counts_only_what_resvg_keeps() {
        // The region runs far beyond the canvas; resvg clips it to 5 x 5 canvases.
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
            <filter id="f" filterUnits="userSpaceOnUse" x="-1e6" y="-1e6" width="2e6" height="2e6">
              <feFlood flood-color="red"/></filter>
            <rect width="10" height="10" filter="url(#f)"/></svg>"#;
        let err = check_tree(&tree(svg), &canvas(1_000)).unwrap_err();
        assert_eq!(err.found, 500 * 500);
    }

    #[test]
    fn a_morphology_with_a_huge_radius_is_refused() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
            <filter id="m"><feMorphology radius="9999"/></filter>
            <rect width="300" height="300" filter="url(#m)"/></svg>"#;
        let err = check_tree(&tree(svg), &canvas(u64::MAX)).unwrap_err();
        assert!(err.what.contains("feMorphology"), "{err:?}");
        let small = svg.replace("9999", "2");
        assert!(check_tree(&tree(&small), &canvas(u64::MAX)).is_ok());
    }

    #[test]
    fn a_pattern_tile_over_the_pixel_limit_is_refused() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
            <pattern id="p" patternUnits="userSpaceOnUse" width="50" height="50"
              patternTransform="scale(100)"><rect width="5" height="5"/></pattern>
            <rect width="100" height="100" fill="url(#p)"/></svg>"#;
        let err = check_tree(&tree(svg), &canvas(1_000_000)).unwrap_err();
        assert!(err.what.contains("pattern id=\"p\""), "{err:?}");
        assert_eq!(err.found, 5000 * 5000);
    }
}
