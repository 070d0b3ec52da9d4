//! The outlines of SVG shapes as kurbo paths, in the shape's own user space.

use kurbo::{BezPath, Circle, Ellipse, Point, Rect, RoundedRect, Shape, Vec2};
use roxmltree::Node;

use super::attr::{error_at, length_attribute};
use crate::error::Error;

/// Shapes whose outline is read.
pub(super) const SHAPES: [&str; 6] = ["rect", "circle", "ellipse", "polygon", "polyline", "path"];

/// How closely circles and ellipses are approximated by cubic Béziers, in user units.
const ARC_TOLERANCE: f64 = 1e-4;

/// The outline of shape `node` in its user space; `None` when the shape draws nothing (a zero
/// width, radius or an empty path). `view` sizes percentages.
pub(super) fn outline(node: Node, view: Rect) -> Result<Option<BezPath>, Error> {
    let (w, h) = (view.width(), view.height());
    let diagonal = (w * w + h * h).sqrt() / std::f64::consts::SQRT_2;
    let len = |name: &str, base: f64| length_attribute(node, name, base, 0.0);
    let path = match node.tag_name().name() {
        "rect" => rect(node, w, h)?,
        "circle" => {
            let r = len("r", diagonal)?;
            let centre = Point::new(len("cx", w)?, len("cy", h)?);
            (r > 0.0).then(|| Circle::new(centre, r).to_path(ARC_TOLERANCE))
        }
        "ellipse" => {
            let (rx, ry) = (len("rx", w)?, len("ry", h)?);
            let centre = Point::new(len("cx", w)?, len("cy", h)?);
            (rx > 0.0 && ry > 0.0)
                .then(|| Ellipse::new(centre, Vec2::new(rx, ry), 0.0).to_path(ARC_TOLERANCE))
        }
        "polygon" | "polyline" => polygon(node),
        _ => {
            let d = node.attribute("d").unwrap_or("");
            let path = BezPath::from_svg(d)
                .map_err(|e| error_at(node, format!("d is not path data ({e})")))?;
            Some(path)
        }
    };
    let path = path.filter(|p| p.elements().len() > 1);
    match path {
        Some(p)
            if p.elements()
                .iter()
                .flat_map(|e| e.end_point())
                .any(|q| !q.is_finite()) =>
        {
            Err(error_at(
                node,
                "the outline has coordinates that are not finite",
            ))
        }
        p => Ok(p),
    }
}

/// A `rect`, with rounded corners from `rx` and `ry` (each defaulting to the other, at most
/// half the side).
fn rect(node: Node, w: f64, h: f64) -> Result<Option<BezPath>, Error> {
    let len = |name: &str, base: f64| length_attribute(node, name, base, 0.0);
    let (width, height) = (len("width", w)?, len("height", h)?);
    if width <= 0.0 || height <= 0.0 {
        return Ok(None);
    }
    let r = Rect::new(0.0, 0.0, width, height) + Vec2::new(len("x", w)?, len("y", h)?);
    let given = |name: &str, base: f64| -> Result<Option<f64>, Error> {
        match node.attribute(name) {
            Some(t) if t.trim() != "auto" => Ok(Some(len(name, base)?.max(0.0))),
            _ => Ok(None),
        }
    };
    let (rx, ry) = match (given("rx", w)?, given("ry", h)?) {
        (None, None) => (0.0, 0.0),
        (Some(x), None) => (x, x),
        (None, Some(y)) => (y, y),
        (Some(x), Some(y)) => (x, y),
    };
    let (rx, ry) = (rx.min(width / 2.0), ry.min(height / 2.0));
    if rx <= 0.0 || ry <= 0.0 {
        return Ok(Some(r.to_path(ARC_TOLERANCE)));
    }
    // Elliptical corners: round with circles of radius rx in a space squeezed by rx / ry.
    let squeeze = rx / ry;
    let squeezed = Rect::new(r.x0, r.y0 * squeeze, r.x1, r.y1 * squeeze);
    let mut path = RoundedRect::from_rect(squeezed, rx).to_path(ARC_TOLERANCE);
    path.apply_affine(kurbo::Affine::scale_non_uniform(1.0, 1.0 / squeeze));
    Ok(Some(path))
}

/// A `polygon` or `polyline`: closed, since only its fill is read. An odd number of
/// coordinates drops the last, as SVG says.
fn polygon(node: Node) -> Option<BezPath> {
    let mut points = svgtypes::PointsParser::from(node.attribute("points").unwrap_or(""));
    let mut path = BezPath::new();
    let (x, y) = points.next()?;
    path.move_to((x, y));
    for (x, y) in points {
        path.line_to((x, y));
    }
    path.close_path();
    Some(path)
}
