//! The rectangle of the plane shown in a picture, the limits on a picture's size and view, and
//! the map from the plane to pixels: what the renderer and the vector export both place their
//! output with.

use kurbo::{Point, Rect};

use crate::error::{Error, ErrorKind};
use crate::mesh::Document;

/// The largest image side accepted.
pub const MAX_SIDE: u32 = 1 << 15;
/// The default largest pixel count
/// ([`RenderOptions::max_pixels`](crate::render::RenderOptions::max_pixels)): 100 megapixels.
pub const MAX_PIXELS: u64 = 100_000_000;
/// The largest magnitude of a view's coordinates (1e150): that of a mesh's.
pub const MAX_VIEW_MAGNITUDE: f64 = crate::validate::MAX_MAGNITUDE;
/// The smallest pixel, in plane units (1e-150): a mesh's shortest edge.
pub const MIN_PIXEL_SIZE: f64 = crate::validate::MIN_EDGE_LENGTH;
/// The smallest pixel relative to the view's largest coordinate (2^-32): smaller pixels leave
/// too few bits of a coordinate to place anti-aliased edges within them.
pub const MIN_RELATIVE_PIXEL_SIZE: f64 = 1.0 / 4_294_967_296.0;

/// The rectangle of the plane shown: `(x0, y0)` is the top-left corner, `(x1, y1)` the
/// bottom-right one. y grows downward, as in SVG.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Left edge.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y1: f64,
}

impl Default for View {
    fn default() -> Self {
        View::new(0.0, 0.0, 256.0, 256.0)
    }
}

impl View {
    /// The rectangle from `(x0, y0)` (top left) to `(x1, y1)` (bottom right).
    pub fn new(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        View { x0, y0, x1, y1 }
    }

    /// The view showing `rect`.
    pub fn from_rect(rect: Rect) -> Self {
        View::new(rect.x0, rect.y0, rect.x1, rect.y1)
    }

    /// The rectangle shown.
    pub fn rect(&self) -> Rect {
        Rect::new(self.x0, self.y0, self.x1, self.y1)
    }

    /// Width in plane units.
    pub fn width(&self) -> f64 {
        self.x1 - self.x0
    }

    /// Height in plane units.
    pub fn height(&self) -> f64 {
        self.y1 - self.y0
    }

    /// The view of a document: its [`document_bounds`] grown by `margin` (a fraction of the larger
    /// side) on every side. An empty document gives the unit square.
    pub fn fit(doc: &Document, margin: f64) -> Self {
        let Some(b) = document_bounds(doc) else {
            return View::new(0.0, 0.0, 1.0, 1.0);
        };
        let side = b.width().max(b.height());
        let side = if side > 0.0 { side } else { 1.0 };
        let m = margin.max(0.0) * side;
        // A degenerate extent (all points on a line) still needs an area.
        let (cx, cy) = (0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1));
        let hw = (0.5 * b.width()).max(0.5 * side * 1e-3) + m;
        let hh = (0.5 * b.height()).max(0.5 * side * 1e-3) + m;
        View::new(cx - hw, cy - hh, cx + hw, cy + hh)
    }

    /// Image dimensions of at most `max_side` pixels that keep this view's aspect ratio.
    pub fn size_for(&self, max_side: u32) -> (u32, u32) {
        let (w, h) = (self.width().abs(), self.height().abs());
        let max_side = max_side.max(1) as f64;
        if w >= h {
            let height = (max_side * h / w).round().max(1.0);
            (max_side as u32, height as u32)
        } else {
            let width = (max_side * w / h).round().max(1.0);
            (width as u32, max_side as u32)
        }
    }
}

/// The bounding box of every control point of every layer, with the tips of the handles given
/// explicitly (default handles lie on their edges). `None` for a document without points.
///
/// The limit surface lies in the convex hull of the points after the ternary step; those are
/// control points, handle tips and face points, and face points stay inside this box unless a
/// handle is longer than half its edge.
pub fn document_bounds(doc: &Document) -> Option<Rect> {
    let mut bounds: Option<Rect> = None;
    let mut add = |p: Point| {
        if p.x.is_finite() && p.y.is_finite() {
            bounds = Some(match bounds {
                None => Rect::from_points(p, p),
                Some(b) => b.union_pt(p),
            });
        }
    };
    for mesh in &doc.layers {
        for p in &mesh.points {
            add(p.position);
        }
        for (&(from, _), &h) in &mesh.handles {
            if let Some(p) = mesh.points.get(from as usize) {
                add(p.position + h);
            }
        }
        for w in &mesh.wedges {
            if let Some(p) = mesh.points.get(w.point as usize) {
                for &h in w.handles.values() {
                    add(p.position + h);
                }
            }
        }
    }
    bounds
}

/// The affine map from the plane to pixel coordinates (pixel `(i, j)` covers
/// `[i, i + 1] x [j, j + 1]`, its centre is at `(i + 0.5, j + 0.5)`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ToPixels {
    pub sx: f64,
    pub sy: f64,
    pub x0: f64,
    pub y0: f64,
}

impl ToPixels {
    pub fn new(view: &View, width: u32, height: u32) -> Self {
        ToPixels {
            sx: width as f64 / view.width(),
            sy: height as f64 / view.height(),
            x0: view.x0,
            y0: view.y0,
        }
    }

    pub fn apply(&self, x: f64, y: f64) -> [f64; 2] {
        [(x - self.x0) * self.sx, (y - self.y0) * self.sy]
    }
}

/// Refuses a `width` x `height` picture of `view`: one without pixels, with more than
/// `max_pixels` pixels or a side above [`MAX_SIDE`], or whose view is empty, not finite, beyond
/// ±[`MAX_VIEW_MAGNITUDE`] or has pixels smaller than [`MIN_PIXEL_SIZE`] or than
/// [`MIN_RELATIVE_PIXEL_SIZE`] times its largest coordinate (adjacent pixels would map to the
/// same plane coordinates).
pub(crate) fn check_image(
    width: u32,
    height: u32,
    view: &View,
    max_pixels: u64,
) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(ErrorKind::Invalid {
            what: "image size".into(),
            message: format!("{width}x{height} has no pixels"),
        }
        .into());
    }
    let pixels = width as u64 * height as u64;
    if pixels > max_pixels {
        return Err(ErrorKind::LimitExceeded {
            what: "pixel count".into(),
            found: pixels,
            limit: max_pixels,
        }
        .into());
    }
    let side = width.max(height);
    if side > MAX_SIDE {
        return Err(ErrorKind::LimitExceeded {
            what: "image side".into(),
            found: side as u64,
            limit: MAX_SIDE as u64,
        }
        .into());
    }
    check_view(view, width, height)
}

/// Refuses a view that is empty or not finite, reaches beyond ±[`MAX_VIEW_MAGNITUDE`], or
/// whose pixels (at `width` x `height`) are smaller than [`MIN_PIXEL_SIZE`] or than
/// [`MIN_RELATIVE_PIXEL_SIZE`] times its largest coordinate.
fn check_view(v: &View, width: u32, height: u32) -> Result<(), Error> {
    let corners = [v.x0, v.y0, v.x1, v.y1];
    let shown = format!("({:?}, {:?}) to ({:?}, {:?})", v.x0, v.y0, v.x1, v.y1);
    let invalid = |message: String| -> Error {
        ErrorKind::Invalid {
            what: "view".into(),
            message: format!("{shown}: {message}"),
        }
        .into()
    };
    if !corners.iter().all(|x| x.is_finite()) {
        return Err(invalid("every coordinate must be a finite number".into()));
    }
    let largest = corners.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if largest > MAX_VIEW_MAGNITUDE {
        return Err(invalid(format!(
            "a coordinate is beyond ±{MAX_VIEW_MAGNITUDE:e}, the largest a mesh may have"
        )));
    }
    if !(v.width() > 0.0 && v.height() > 0.0) {
        return Err(invalid("x1 must exceed x0 and y1 must exceed y0".into()));
    }
    let pixel = (v.width() / width as f64).min(v.height() / height as f64);
    let smallest = MIN_PIXEL_SIZE.max(MIN_RELATIVE_PIXEL_SIZE * largest);
    if pixel < smallest {
        return Err(invalid(format!(
            "a pixel would be {pixel:e} units across, below the {smallest:e} that \
             coordinates of this size resolve"
        )));
    }
    Ok(())
}
