//! The normalised picture a PDF page is read into: its patch-mesh shadings in picture
//! coordinates (the crop box, y down, one unit per point).

use kurbo::{BezPath, Point, Rect};

use super::colour::ShadingColour;
use crate::formats::svg::FillRule;

/// The patch-mesh shadings of one page of a PDF file, in paint order.
///
/// Guarantees after [`read_pdf`](super::read_pdf):
/// * every coordinate is in picture units: the page's crop box turned by its `/Rotate`, with
///   its top-left corner at the origin, y down, one unit per point; the CTM, the pattern matrix
///   and the form matrices are applied;
/// * every number is finite;
/// * every fill has at least one patch.
#[derive(Clone, Debug, PartialEq)]
pub struct PdfPicture {
    /// The page read, from 1.
    pub page: usize,
    /// The number of pages of the file.
    pub pages: usize,
    /// The crop box in the page's default user space (y up), as the file gives it.
    pub crop_box: Rect,
    /// The page's `/Rotate`: 0, 90, 180 or 270 degrees clockwise, applied to the picture.
    pub rotation: u16,
    /// The patch-mesh shadings painted on the page, bottom first.
    pub fills: Vec<ShadingFill>,
    /// What was read but is not in `fills`, or was read approximately, naming the object.
    pub warnings: Vec<String>,
}

impl PdfPicture {
    /// The rectangle of picture units the page shows: `(0, 0)` to the crop box's size, width
    /// and height swapped when the page is turned a quarter.
    pub fn view_rect(&self) -> Rect {
        let (w, h) = (self.crop_box.width(), self.crop_box.height());
        match self.rotation {
            90 | 270 => Rect::new(0.0, 0.0, h, w),
            _ => Rect::new(0.0, 0.0, w, h),
        }
    }
}

/// One type 6 or type 7 shading as painted once on the page (by `sh`, or as the pattern of a
/// fill).
#[derive(Clone, Debug, PartialEq)]
pub struct ShadingFill {
    /// The shading's object (`"object 12"`), or `"an inline shading"`.
    pub object: String,
    /// 6 (Coons patch mesh) or 7 (tensor-product patch mesh).
    pub shading_type: u8,
    /// The patches in stream order, in picture units.
    pub patches: Vec<Patch>,
    /// How the corner components become colours.
    pub colour: ShadingColour,
    /// The outline the shading is painted inside (the path filled with the pattern, the clipping
    /// path, the shading's `BBox`), when there is one.
    pub clip: Option<(BezPath, FillRule)>,
    /// The constant opacity of the graphics state (`ca`), in 0..1.
    pub opacity: f64,
    /// The opacity of each patch's corners ((0, 0), (0, 1), (1, 0), (1, 1)) from a luminosity
    /// soft mask holding one grey shading of the same patches, as gradmesh's export and Cairo
    /// write them; bilinear in the patch's parameters, times `opacity`.
    pub corner_opacity: Option<Vec<[f64; 4]>>,
}

impl ShadingFill {
    /// The smallest rectangle holding every control point of every patch.
    pub fn control_bounds(&self) -> Rect {
        let mut points = self
            .patches
            .iter()
            .flat_map(|p| p.points.iter().flatten().copied());
        let first = points.next().unwrap_or_default();
        points.fold(Rect::from_points(first, first), |r, p| r.union_pt(p))
    }

    /// The opacity of patch number `index` at parameters `(u, v)`.
    pub fn opacity_at(&self, index: usize, u: f64, v: f64) -> f64 {
        match self.corner_opacity.as_ref().and_then(|c| c.get(index)) {
            Some(o) => {
                let top = o[0] * (1.0 - v) + o[1] * v;
                let bottom = o[2] * (1.0 - v) + o[3] * v;
                self.opacity * (top * (1.0 - u) + bottom * u)
            }
            None => self.opacity,
        }
    }

    /// The sRGB colour (gamma-encoded, 0..1) of patch `patch` at parameters `(u, v)`: the
    /// corner components interpolated bilinearly, then converted, as the PDF specification
    /// says.
    pub fn srgb_at(&self, patch: &Patch, u: f64, v: f64) -> [f64; 3] {
        let n = patch.components.len() / 4;
        let mut c = [0.0; 4];
        for (k, value) in c.iter_mut().enumerate().take(n.min(4)) {
            let at = |corner: usize| patch.components[corner * n + k];
            let top = at(0) * (1.0 - v) + at(1) * v;
            let bottom = at(2) * (1.0 - v) + at(3) * v;
            *value = top * (1.0 - u) + bottom * u;
        }
        self.colour.to_srgb(&c[..n.min(4)])
    }
}

/// A tensor-product patch: `S(u, v) = Σ p[i][j] B_i(u) B_j(v)` (Bernstein polynomials of
/// degree 3), `i` along `u`. A Coons patch (type 6) is stored with its implied interior points.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// The 16 control points, `points[i][j]`.
    pub points: [[Point; 4]; 4],
    /// The components of the corners `(u, v)` = (0, 0), (0, 1), (1, 0), (1, 1), each as many
    /// as the shading has (one parametric value with a `Function`), corner after corner.
    pub components: Vec<f64>,
}

impl Patch {
    /// A flat patch over `rect` whose four corners have the components `components`.
    pub fn flat(rect: Rect, components: &[f64]) -> Patch {
        let mut points = [[Point::ZERO; 4]; 4];
        for (i, row) in points.iter_mut().enumerate() {
            for (j, point) in row.iter_mut().enumerate() {
                *point = Point::new(
                    rect.x0 + rect.width() * i as f64 / 3.0,
                    rect.y0 + rect.height() * j as f64 / 3.0,
                );
            }
        }
        Patch {
            points,
            components: components.repeat(4),
        }
    }

    /// The surface at `(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> Point {
        let bu = bernstein(u);
        let bv = bernstein(v);
        let (mut x, mut y) = (0.0, 0.0);
        for (i, row) in self.points.iter().enumerate() {
            for (j, p) in row.iter().enumerate() {
                let w = bu[i] * bv[j];
                x += w * p.x;
                y += w * p.y;
            }
        }
        Point::new(x, y)
    }

    /// The boundary curves as cubic control points, in the order the patch's stream record
    /// walks them: `v` rising at `u = 0`, `u` rising at `v = 1`, `v` falling at `u = 1`, `u`
    /// falling at `v = 0`.
    pub fn sides(&self) -> [[Point; 4]; 4] {
        let p = &self.points;
        [
            [p[0][0], p[0][1], p[0][2], p[0][3]],
            [p[0][3], p[1][3], p[2][3], p[3][3]],
            [p[3][3], p[3][2], p[3][1], p[3][0]],
            [p[3][0], p[2][0], p[1][0], p[0][0]],
        ]
    }

    /// The signed area of the polygon of the four corners (positive when the corners (0, 0),
    /// (0, 1), (1, 1), (1, 0) run clockwise on the y-down picture).
    pub fn corner_area(&self) -> f64 {
        let c = [
            self.points[0][0],
            self.points[0][3],
            self.points[3][3],
            self.points[3][0],
        ];
        (0..4)
            .map(|k| {
                let (a, b) = (c[k], c[(k + 1) % 4]);
                a.x * b.y - b.x * a.y
            })
            .sum::<f64>()
            / 2.0
    }
}

/// The cubic Bernstein polynomials at `t`.
pub(crate) fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// The interior points a Coons patch implies (`points[1..3][1..3]` from its boundary), as the
/// PDF specification gives them.
pub(crate) fn coons_interior(p: &mut [[Point; 4]; 4]) {
    let v = |q: Point| q.to_vec2();
    let inner = |i: usize, j: usize| {
        // The corner nearest (i, j), the two boundary points beside it, the far ones.
        let (ci, cj) = (if i == 1 { 0 } else { 3 }, if j == 1 { 0 } else { 3 });
        let (fi, fj) = (3 - ci, 3 - cj);
        let (ni, nj) = (if ci == 0 { 1 } else { 2 }, if cj == 0 { 1 } else { 2 });
        let sum = v(p[ci][cj]) * -4.0 + (v(p[ci][nj]) + v(p[ni][cj])) * 6.0
            - (v(p[ci][fj]) + v(p[fi][cj])) * 2.0
            + (v(p[fi][nj]) + v(p[ni][fj])) * 3.0
            - v(p[fi][fj]);
        (sum / 9.0).to_point()
    };
    let values = [(1, 1), (1, 2), (2, 1), (2, 2)].map(|(i, j)| ((i, j), inner(i, j)));
    for ((i, j), q) in values {
        p[i][j] = q;
    }
}

/// A clipping path and its rule.
#[cfg(feature = "pdf-read")]
pub(crate) type ClipPath = (BezPath, FillRule);

/// The stream positions of the points of a type 7 record with flag 0: `(i, j)` of `p[i][j]`,
/// `i` along `u` (the writer's order too).
pub(crate) const POINT_ORDER: [(usize, usize); 16] = [
    (0, 0),
    (0, 1),
    (0, 2),
    (0, 3),
    (1, 3),
    (2, 3),
    (3, 3),
    (3, 2),
    (3, 1),
    (3, 0),
    (2, 0),
    (1, 0),
    (1, 1),
    (1, 2),
    (2, 2),
    (2, 1),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// With the implied interior points, the tensor patch is the Coons patch of its sides:
    /// the two ruled surfaces less the bilinear one.
    #[test]
    fn coons_interior_gives_the_coons_surface() {
        let mut points = [[Point::ZERO; 4]; 4];
        let boundary = [
            (0, 0, 0.0, 0.0),
            (0, 1, 3.0, 31.0),
            (0, 2, 7.0, 66.0),
            (0, 3, 1.0, 100.0),
            (1, 3, 30.0, 104.0),
            (2, 3, 70.0, 93.0),
            (3, 3, 100.0, 100.0),
            (3, 2, 104.0, 60.0),
            (3, 1, 96.0, 30.0),
            (3, 0, 100.0, 2.0),
            (2, 0, 60.0, -9.0),
            (1, 0, 33.0, 5.0),
        ];
        for (i, j, x, y) in boundary {
            points[i][j] = Point::new(x, y);
        }
        coons_interior(&mut points);
        let patch = Patch {
            points,
            components: vec![0.0; 4],
        };
        let curve = |s: [Point; 4], t: f64| {
            let b = bernstein(t);
            (0..4).fold(kurbo::Vec2::ZERO, |acc, k| acc + s[k].to_vec2() * b[k])
        };
        let p = &patch.points;
        for (u, v) in [(0.3, 0.6), (0.5, 0.5), (0.9, 0.1)] {
            let at_u0 = curve([p[0][0], p[0][1], p[0][2], p[0][3]], v);
            let at_u1 = curve([p[3][0], p[3][1], p[3][2], p[3][3]], v);
            let at_v0 = curve([p[0][0], p[1][0], p[2][0], p[3][0]], u);
            let at_v1 = curve([p[0][3], p[1][3], p[2][3], p[3][3]], u);
            let corners = p[0][0].to_vec2() * ((1.0 - u) * (1.0 - v))
                + p[0][3].to_vec2() * ((1.0 - u) * v)
                + p[3][0].to_vec2() * (u * (1.0 - v))
                + p[3][3].to_vec2() * (u * v);
            let coons = at_u0 * (1.0 - u) + at_u1 * u + at_v0 * (1.0 - v) + at_v1 * v - corners;
            let tensor = patch.eval(u, v).to_vec2();
            assert!(
                (coons - tensor).hypot() < 1e-9,
                "{u} {v}: {coons:?} {tensor:?}"
            );
        }
    }
}
