//! The rectangle of the plane shown in an image, and the map from the plane to pixels.

use kurbo::{Point, Rect};

use crate::mesh::Document;

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
