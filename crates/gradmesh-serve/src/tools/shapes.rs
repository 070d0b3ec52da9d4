//! New meshes: a grid over a rectangle, a mesh inside an ellipse, a mesh inside a drawn outline.
//!
//! Their colours are the corner palette ([`super::palette`]) blended over the shape's box, so a
//! new mesh shows its points apart; faces run the way `add_rectangle`'s do (left, top, right,
//! bottom in a plane with y down).

use std::f64::consts::PI;

use gradmesh::GradientMesh;
use kurbo::{Point, Vec2};

use super::{palette_at, Selection, ToolResult};

/// The most rows or columns of a new grid.
pub const MAX_GRID: u32 = 64;

/// The most corners of a drawn outline.
pub const MAX_OUTLINE_POINTS: usize = 64;

/// The rectangle `[x0, y0, x1, y1]` (any two opposite corners) as left, top, right, bottom;
/// refused when it is not finite or has no area.
fn normalised(rect: [f64; 4]) -> Result<[f64; 4], String> {
    if rect.iter().any(|c| !c.is_finite()) {
        return Err("the rectangle's corners must be finite numbers".into());
    }
    let [x0, y0, x1, y1] = rect;
    let r = [x0.min(x1), y0.min(y1), x0.max(x1), y0.max(y1)];
    if r[2] - r[0] <= 0.0 || r[3] - r[1] <= 0.0 {
        return Err("the rectangle has no area: drag over the place the mesh should fill".into());
    }
    Ok(r)
}

/// Adds a point at `at` coloured from the palette at its place in `rect`.
fn add_palette_point(mesh: &mut GradientMesh, rect: [f64; 4], at: Point) -> u32 {
    let u = (at.x - rect[0]) / (rect[2] - rect[0]);
    let v = (at.y - rect[1]) / (rect[3] - rect[1]);
    let colour = palette_at(mesh.colour_space, u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
    mesh.add_point(at, colour)
}

fn selection_from(first: usize, mesh: &GradientMesh) -> ToolResult {
    ToolResult {
        selection: Selection {
            layer: 0,
            points: (first as u32..mesh.points.len() as u32).collect(),
            face: None,
        },
        note: None,
    }
}

/// Adds a grid of `columns` x `rows` quads (1 to [`MAX_GRID`] each) over `rect`; selects its
/// points.
pub fn add_grid(
    mesh: &mut GradientMesh,
    rect: [f64; 4],
    columns: u32,
    rows: u32,
) -> Result<ToolResult, String> {
    let rect = normalised(rect)?;
    for (n, what) in [(columns, "columns"), (rows, "rows")] {
        if !(1..=MAX_GRID).contains(&n) {
            return Err(format!("a grid has 1 to {MAX_GRID} {what} (asked for {n})"));
        }
    }
    let first = mesh.points.len();
    let (w, h) = (rect[2] - rect[0], rect[3] - rect[1]);
    let index = |i: u32, j: u32| (first as u32) + j * (columns + 1) + i;
    for j in 0..=rows {
        for i in 0..=columns {
            let at = Point::new(
                rect[0] + w * f64::from(i) / f64::from(columns),
                rect[1] + h * f64::from(j) / f64::from(rows),
            );
            add_palette_point(mesh, rect, at);
        }
    }
    for j in 0..rows {
        for i in 0..columns {
            mesh.add_face(vec![
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            ]);
        }
    }
    Ok(selection_from(first, mesh))
}

/// Adds a mesh filling the ellipse inscribed in `rect`: a 2 x 2 grid in the middle ringed by
/// 8 quads whose outer edges follow the ellipse (cubic arcs of 45 degrees). The grid's corners
/// have three edges each, the irregular vertices a disc of quads needs. Selects its points.
pub fn add_ellipse(mesh: &mut GradientMesh, rect: [f64; 4]) -> Result<ToolResult, String> {
    let rect = normalised(rect)?;
    let centre = Point::new((rect[0] + rect[2]) / 2.0, (rect[1] + rect[3]) / 2.0);
    let radii = Vec2::new((rect[2] - rect[0]) / 2.0, (rect[3] - rect[1]) / 2.0);
    // A unit disc mapped onto the ellipse.
    let place = |x: f64, y: f64| centre + Vec2::new(x * radii.x, y * radii.y);
    let first = mesh.points.len() as u32;
    // The inner 3 x 3 points; the corners pulled in so that the ring's quads are even.
    let inner = |i: i32, j: i32| {
        let s = if i != 0 && j != 0 { 0.42 } else { 0.5 };
        place(f64::from(i) * s, f64::from(j) * s)
    };
    for j in -1..=1 {
        for i in -1..=1 {
            add_palette_point(mesh, rect, inner(i, j));
        }
    }
    let grid = |i: i32, j: i32| first + ((j + 1) * 3 + (i + 1)) as u32;
    for (i, j) in [(-1, -1), (0, -1), (-1, 0), (0, 0)] {
        mesh.add_face(vec![
            grid(i, j),
            grid(i + 1, j),
            grid(i + 1, j + 1),
            grid(i, j + 1),
        ]);
    }
    // The ring: 8 points on the ellipse at 45 degrees apart, each facing one of the grid's
    // boundary points, in the order of increasing angle.
    let facing = [
        (1, 0),
        (1, 1),
        (0, 1),
        (-1, 1),
        (-1, 0),
        (-1, -1),
        (0, -1),
        (1, -1),
    ];
    let angle = |k: usize| k as f64 * PI / 4.0;
    let outer: Vec<u32> = (0..8)
        .map(|k| add_palette_point(mesh, rect, place(angle(k).cos(), angle(k).sin())))
        .collect();
    // A 45-degree arc of the unit circle has handles of this length along its tangents.
    let reach = 4.0 / 3.0 * (PI / 16.0).tan();
    for k in 0..8 {
        let next = (k + 1) % 8;
        let (i, j) = facing[k];
        let (ni, nj) = facing[next];
        mesh.add_face(vec![outer[k], outer[next], grid(ni, nj), grid(i, j)]);
        let tangent = |a: f64| Vec2::new(-a.sin() * radii.x, a.cos() * radii.y) * reach;
        mesh.set_handle(outer[k], outer[next], tangent(angle(k)));
        mesh.set_handle(outer[next], outer[k], -tangent(angle(k + 1)));
    }
    Ok(selection_from(first as usize, mesh))
}

/// Twice the signed area of a polygon (positive when it runs as `add_rectangle`'s faces do).
fn signed_area2(points: &[Point]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| points[i].to_vec2().cross(points[(i + 1) % n].to_vec2()))
        .sum()
}

/// The area centroid of a polygon of non-zero area.
fn centroid(points: &[Point], area2: f64) -> Point {
    let n = points.len();
    let mut c = Vec2::ZERO;
    for i in 0..n {
        let (p, q) = (points[i].to_vec2(), points[(i + 1) % n].to_vec2());
        c += (p + q) * p.cross(q);
    }
    (c / (3.0 * area2)).to_point()
}

/// Whether segments `ab` and `cd` cross or touch.
fn segments_meet(a: Point, b: Point, c: Point, d: Point) -> bool {
    let side = |p: Point, q: Point, r: Point| (q - p).cross(r - p);
    let (d1, d2) = (side(c, d, a), side(c, d, b));
    let (d3, d4) = (side(a, b, c), side(a, b, d));
    if ((d1 > 0.0) != (d2 > 0.0)) && ((d3 > 0.0) != (d4 > 0.0)) && d1 != 0.0 && d2 != 0.0 {
        return true;
    }
    let on = |p: Point, q: Point, r: Point| {
        side(p, q, r) == 0.0
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on(a, b, c) || on(a, b, d) || on(c, d, a) || on(c, d, b)
}

/// The outline cleaned (finite, without repeated points, running as faces run, an even number
/// of corners) or why it cannot be meshed.
fn clean_outline(outline: &[[f64; 2]]) -> Result<Vec<Point>, String> {
    if outline.iter().flatten().any(|c| !c.is_finite()) {
        return Err("the outline's points must be finite numbers".into());
    }
    let mut points: Vec<Point> = Vec::with_capacity(outline.len());
    for &[x, y] in outline {
        let p = Point::new(x, y);
        if points.last() != Some(&p) {
            points.push(p);
        }
    }
    while points.len() > 1 && points.first() == points.last() {
        points.pop();
    }
    if points.len() < 3 {
        return Err("an outline needs three or more different points".into());
    }
    if points.len() > MAX_OUTLINE_POINTS {
        return Err(format!(
            "an outline has at most {MAX_OUTLINE_POINTS} corners (this one has {})",
            points.len()
        ));
    }
    let n = points.len();
    for i in 0..n {
        for j in i + 1..n {
            let neighbours = j == i + 1 || (i == 0 && j == n - 1);
            if !neighbours
                && segments_meet(
                    points[i],
                    points[(i + 1) % n],
                    points[j],
                    points[(j + 1) % n],
                )
            {
                return Err(format!(
                    "the outline crosses itself (its sides {} and {} meet): draw it without crossings",
                    i + 1,
                    j + 1
                ));
            }
        }
    }
    if signed_area2(&points) < 0.0 {
        points.reverse();
    }
    if points.len() % 2 == 1 {
        // An even number of corners fills the middle with quads: the longest side gets a corner
        // in its middle.
        let longest = (0..points.len())
            .max_by(|&i, &j| {
                let len = |k: usize| (points[(k + 1) % points.len()] - points[k]).hypot();
                len(i).total_cmp(&len(j))
            })
            .expect("three or more points");
        let middle = points[longest].midpoint(points[(longest + 1) % points.len()]);
        points.insert(longest + 1, middle);
    }
    Ok(points)
}

/// Adds a mesh filling the polygon `outline` (its corners in order, 3 to
/// [`MAX_OUTLINE_POINTS`]): a ring of quads along the outline around an inner copy shrunk
/// halfway to the centroid, and quads from the centroid to every other inner point (two
/// triangles where such a quad would not be convex; an odd outline gets a point in the middle
/// of its longest side first). Refuses outlines that cross themselves and those not every
/// point of which is seen from the centroid, with a message. Selects its points.
pub fn add_outline(mesh: &mut GradientMesh, outline: &[[f64; 2]]) -> Result<ToolResult, String> {
    let points = clean_outline(outline)?;
    let n = points.len();
    let area2 = signed_area2(&points);
    let size = points
        .iter()
        .map(|&p| (p - points[0]).hypot())
        .fold(0.0, f64::max);
    if area2.abs() <= 1e-12 * size * size {
        return Err("the outline encloses no area".into());
    }
    let c = centroid(&points, area2);
    for i in 0..n {
        let (p, q) = (points[i] - c, points[(i + 1) % n] - c);
        if p.cross(q) <= 1e-9 * p.hypot() * q.hypot() {
            return Err(format!(
                "the outline is not seen whole from its middle (its side {} faces away): \
                 draw a rounder shape, or the shape in pieces",
                i + 1
            ));
        }
    }
    let rect = bounds(&points);
    let first = mesh.points.len();
    let outer: Vec<u32> = (points.iter())
        .map(|&p| add_palette_point(mesh, rect, p))
        .collect();
    let inner_at: Vec<Point> = points.iter().map(|&p| c.lerp(p, 0.5)).collect();
    let inner: Vec<u32> = (inner_at.iter())
        .map(|&p| add_palette_point(mesh, rect, p))
        .collect();
    let middle = add_palette_point(mesh, rect, c);
    for i in 0..n {
        let j = (i + 1) % n;
        mesh.add_face(vec![outer[i], outer[j], inner[j], inner[i]]);
    }
    for k in (0..n).step_by(2) {
        let (a, b, d) = (k, k + 1, (k + 2) % n);
        if convex(&[inner_at[a], inner_at[b], inner_at[d], c]) {
            mesh.add_face(vec![inner[a], inner[b], inner[d], middle]);
        } else {
            mesh.add_face(vec![inner[a], inner[b], middle]);
            mesh.add_face(vec![inner[b], inner[d], middle]);
        }
    }
    Ok(selection_from(first, mesh))
}

fn bounds(points: &[Point]) -> [f64; 4] {
    let mut r = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in points {
        r = [r[0].min(p.x), r[1].min(p.y), r[2].max(p.x), r[3].max(p.y)];
    }
    r
}

/// Whether the polygon turns the same way (positive) at every corner, or goes straight on
/// (within rounding): the point added on an outline's longest side lies on it, and its inner
/// point on the line of its neighbours', which rounding alone would otherwise decide.
fn convex(points: &[Point]) -> bool {
    let n = points.len();
    (0..n).all(|i| {
        let (p, q, r) = (points[i], points[(i + 1) % n], points[(i + 2) % n]);
        let (a, b) = (q - p, r - q);
        a.cross(b) > -1e-9 * a.hypot() * b.hypot()
    })
}
