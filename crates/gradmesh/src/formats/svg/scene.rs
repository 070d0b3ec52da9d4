//! The normalised picture an SVG file is read into: mesh-gradient fills in root user units.

use kurbo::{BezPath, CubicBez, Point, Rect};

use crate::error::Warning;

/// What an SVG document holds that gradmesh draws: every shape filled with a mesh gradient, in
/// paint order, with everything resolved.
///
/// Guarantees after [`read_svg`](super::read_svg):
/// * every coordinate is in the root `<svg>` element's user units (the units of its `viewBox`):
///   the `gradientTransform`, the `objectBoundingBox` mapping, `x`/`y`, and the `transform` of
///   the shape and of all its ancestors are applied; the `viewBox`-to-viewport mapping is not;
/// * every number is finite;
/// * every mesh is a full grid of at least one patch, whose neighbouring patches share their
///   sides exactly (one curve is stored per side);
/// * colours are sRGB in 0..1 and opacities in 0..1;
/// * `href` chains are resolved: no reference remains.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgScene {
    /// The root's `viewBox`, when it has a valid one.
    pub view_box: Option<Rect>,
    /// The root's `preserveAspectRatio`.
    pub aspect: AspectRatio,
    /// The root's `width`, in CSS pixels, when given as a positive absolute length.
    pub width: Option<f64>,
    /// The root's `height`, in CSS pixels, when given as a positive absolute length.
    pub height: Option<f64>,
    /// The shapes filled with a mesh gradient, bottom first.
    pub fills: Vec<MeshFill>,
    /// What was read but is not in `fills`, naming the element: content with other paints,
    /// strokes, text, images, and values replaced by defaults.
    pub warnings: Vec<Warning>,
}

/// CSS's size of a replaced element that gives none, in pixels.
pub const DEFAULT_SIZE: (f64, f64) = (300.0, 150.0);

impl SvgScene {
    /// The picture's size in CSS pixels: the root's `width` and `height`; a side missing (or
    /// zero) follows from the other and the view box's aspect ratio, or is the view box's
    /// when both are missing (as Inkscape and resvg size such files); without a view box,
    /// CSS's default of 300 x 150.
    pub fn pixel_size(&self) -> (f64, f64) {
        match (self.width, self.height, self.view_box) {
            (Some(w), Some(h), _) => (w, h),
            (Some(w), None, Some(b)) => (w, w * b.height() / b.width()),
            (None, Some(h), Some(b)) => (h * b.width() / b.height(), h),
            (None, None, Some(b)) => (b.width(), b.height()),
            (w, h, None) => (w.unwrap_or(DEFAULT_SIZE.0), h.unwrap_or(DEFAULT_SIZE.1)),
        }
    }

    /// The rectangle of user space the picture shows: the view box fitted into the picture
    /// ([`SvgScene::pixel_size`]) as `preserveAspectRatio` says (with `meet` it grows to fill
    /// the picture, with `slice` it is cut to it), or else `(0, 0)` to the picture's size.
    pub fn view_rect(&self) -> Rect {
        let (w, h) = self.pixel_size();
        match self.view_box {
            Some(b) => self.aspect.fit(b, w, h),
            None => Rect::new(0.0, 0.0, w, h),
        }
    }
}

/// How the view box is fitted into the viewport (`preserveAspectRatio`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AspectRatio {
    /// Where the view box goes along x and along y within the viewport: 0 at the start
    /// (`xMin`, `yMin`), 0.5 in the middle, 1 at the end; `None` for `none` (stretched).
    pub align: Option<(f64, f64)>,
    /// `slice` (the view box covers the viewport and is cut) rather than `meet` (the view box
    /// lies wholly inside the viewport).
    pub slice: bool,
}

impl Default for AspectRatio {
    /// `xMidYMid meet`, the initial value.
    fn default() -> Self {
        AspectRatio {
            align: Some((0.5, 0.5)),
            slice: false,
        }
    }
}

impl AspectRatio {
    /// The rectangle of user space that a `width` x `height` viewport shows of view box
    /// `view_box`: the view box scaled uniformly and placed as `align` says. Aspect ratios
    /// within a millionth of each other are taken as equal (editors write sizes such as
    /// 600.00005 x 399.99998 for 600 x 400): the view box itself.
    pub fn fit(&self, view_box: Rect, width: f64, height: f64) -> Rect {
        let Some((ax, ay)) = self.align else {
            return view_box;
        };
        let (sx, sy) = (width / view_box.width(), height / view_box.height());
        if (sx - sy).abs() <= 1e-6 * sx.max(sy) {
            return view_box;
        }
        let scale = if self.slice { sx.max(sy) } else { sx.min(sy) };
        if !(scale.is_finite() && scale > 0.0) {
            return view_box;
        }
        let (w, h) = (width / scale, height / scale);
        let x0 = view_box.x0 - (w - view_box.width()) * ax;
        let y0 = view_box.y0 - (h - view_box.height()) * ay;
        Rect::new(x0, y0, x0 + w, y0 + h)
    }
}

/// The rule that tells the inside of a shape's outline from the outside (`fill-rule`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FillRule {
    /// `fill-rule: nonzero` (the default).
    NonZero,
    /// `fill-rule: evenodd`.
    EvenOdd,
}

/// One shape filled with a mesh gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFill {
    /// The shape's `id`, when it has one.
    pub shape_id: Option<String>,
    /// The shape's element name (`rect`, `path`, ...).
    pub shape_tag: String,
    /// The `id` of the mesh gradient the shape names in its `fill`.
    pub gradient_id: String,
    /// The outline of the shape in root user units: the mesh is visible only inside it.
    pub clip: BezPath,
    /// How `clip` decides inside from outside.
    pub fill_rule: FillRule,
    /// `fill-opacity` of the shape, in 0..1: multiplies every corner's opacity.
    pub fill_opacity: f64,
    /// The product of the `opacity` of the shape and of its ancestors, in 0..1: applied to the
    /// shape as a whole, after the mesh is painted.
    pub group_opacity: f64,
    /// The mesh, in root user units.
    pub mesh: MeshGrid,
}

/// How the colours of a mesh are interpolated (the gradient's `type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshType {
    /// `bilinear` (SVG 2 draft, its initial value): bilinear in each patch's parameters.
    Bilinear,
    /// `coons` (Inkscape's name and default), painted as `bilinear`.
    Coons,
    /// `bicubic`: colours smoothed across patches.
    Bicubic,
}

impl MeshType {
    /// The attribute value.
    pub fn name(self) -> &'static str {
        match self {
            MeshType::Bilinear => "bilinear",
            MeshType::Coons => "coons",
            MeshType::Bicubic => "bicubic",
        }
    }
}

/// A patch corner: where it is, and the colour of the stop that starts there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corner {
    /// Position in root user units.
    pub position: Point,
    /// sRGB colour (gamma-encoded), each channel in 0..1.
    pub colour: [f64; 3],
    /// `stop-opacity` (times the alpha of the colour, if it had one), in 0..1.
    pub opacity: f64,
}

/// A mesh gradient: `rows` x `columns` Coons patches.
///
/// Corner `(i, j)` (row `i` in `0..=rows`, column `j` in `0..=columns`) is at
/// `corners[i * (columns + 1) + j]`. Patch `(r, c)` has corners `(r, c)` top left, `(r, c + 1)`
/// top right, `(r + 1, c + 1)` bottom right and `(r + 1, c)` bottom left, as the SVG draft
/// names them ("top" is the side the first row's first stop draws, whatever the transform).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshGrid {
    /// The gradient's `type`.
    pub kind: MeshType,
    /// Number of rows of patches (at least 1).
    pub rows: usize,
    /// Number of patches in each row (at least 1).
    pub columns: usize,
    /// `(rows + 1) * (columns + 1)` corners, row by row.
    pub corners: Vec<Corner>,
    /// The sides that run along the rows: `(rows + 1) * columns` curves, the one from corner
    /// `(i, j)` to corner `(i, j + 1)` at `i * columns + j`.
    pub row_sides: Vec<CubicBez>,
    /// The sides that run down the columns: `rows * (columns + 1)` curves, the one from corner
    /// `(i, j)` to corner `(i + 1, j)` at `i * (columns + 1) + j`.
    pub column_sides: Vec<CubicBez>,
}

impl MeshGrid {
    /// The corner at row `i`, column `j`.
    pub fn corner(&self, i: usize, j: usize) -> &Corner {
        &self.corners[i * (self.columns + 1) + j]
    }

    /// The side from corner `(i, j)` to `(i, j + 1)`.
    pub fn row_side(&self, i: usize, j: usize) -> CubicBez {
        self.row_sides[i * self.columns + j]
    }

    /// The side from corner `(i, j)` to `(i + 1, j)`.
    pub fn column_side(&self, i: usize, j: usize) -> CubicBez {
        self.column_sides[i * (self.columns + 1) + j]
    }

    /// The four sides of patch `(r, c)` as the patch's stops run them: top (left to right),
    /// right (downwards), bottom (right to left), left (upwards).
    pub fn patch_sides(&self, r: usize, c: usize) -> [CubicBez; 4] {
        let reversed = |s: CubicBez| CubicBez::new(s.p3, s.p2, s.p1, s.p0);
        [
            self.row_side(r, c),
            self.column_side(r, c + 1),
            reversed(self.row_side(r + 1, c)),
            reversed(self.column_side(r, c)),
        ]
    }

    /// The smallest rectangle holding every control point of every side (it holds the mesh).
    pub fn control_bounds(&self) -> Rect {
        let mut points = self
            .row_sides
            .iter()
            .chain(&self.column_sides)
            .flat_map(|s| [s.p0, s.p1, s.p2, s.p3]);
        let first = points.next().unwrap_or_default();
        points.fold(Rect::from_points(first, first), |r, p| r.union_pt(p))
    }
}
