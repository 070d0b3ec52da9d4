//! The opaque part of a picture with transparent pixels, and the mesh that covers it: the
//! vectoriser keeps the cells of its quadtree that are mostly opaque, splits the cells the
//! silhouette crosses, and moves the outline's points onto it.

use std::collections::HashMap;

use kurbo::Point;

use crate::union_find::UnionFind;

use super::image::RgbaImage;
use super::quadtree::{Cell, Quadtree, TreeMesh};

/// The opacity from which a pixel counts as inside the silhouette.
const INSIDE_ALPHA: f32 = 0.5;

/// What a pixel on the wrong side of the outline costs when choosing cells to split: its
/// three 8-bit channels wholly wrong, as a missing or extra pixel of colour looks.
pub(crate) const MISCOVERED_PIXEL_ERROR: f64 = 3.0 * 255.0 * 255.0;

/// Which pixels of a picture are inside (alpha at least one half), with a summed-area table
/// for counting them in a rectangle.
pub(crate) struct Silhouette {
    width: usize,
    height: usize,
    inside: Vec<bool>,
    /// `(width + 1) x (height + 1)`: the inside pixels above and left of each corner.
    sums: Vec<u32>,
}

impl Silhouette {
    /// The silhouette of `image`, or `None` when every pixel is inside (an opaque picture:
    /// the mesh covers all of it).
    pub fn of(image: &RgbaImage) -> Option<Silhouette> {
        let inside: Vec<bool> = image.pixels.iter().map(|p| p[3] >= INSIDE_ALPHA).collect();
        if inside.iter().all(|&i| i) {
            return None;
        }
        let (width, height) = (image.width as usize, image.height as usize);
        let mut sums = vec![0u32; (width + 1) * (height + 1)];
        for y in 0..height {
            let mut row = 0;
            for x in 0..width {
                row += inside[y * width + x] as u32;
                sums[(y + 1) * (width + 1) + x + 1] = sums[y * (width + 1) + x + 1] + row;
            }
        }
        Some(Silhouette {
            width,
            height,
            inside,
            sums,
        })
    }

    /// Whether no pixel is inside.
    pub fn is_empty(&self) -> bool {
        self.sums.last() == Some(&0)
    }

    /// The pixels whose centres lie in the rectangle from `a` to `b`: inside, and in all.
    fn count(&self, a: Point, b: Point) -> (u32, u32) {
        let column = |x: f64| ((x - 0.5).ceil().max(0.0) as usize).min(self.width);
        let row = |y: f64| ((y - 0.5).ceil().max(0.0) as usize).min(self.height);
        let (x0, x1, y0, y1) = (column(a.x), column(b.x), row(a.y), row(b.y));
        let at = |x: usize, y: usize| self.sums[y * (self.width + 1) + x];
        let inside = at(x1, y1) + at(x0, y0) - at(x0, y1) - at(x1, y0);
        (inside, ((x1 - x0) * (y1 - y0)) as u32)
    }

    /// The pixels of leaf `cell` of `tree` inside, the pixels in all, and whether the leaf is
    /// kept as a face: at least half its pixels are inside.
    fn coverage(&self, tree: &Quadtree, cell: &Cell) -> (u32, u32, bool) {
        let (a, b) = tree.cell_corners(cell);
        let (inside, all) = self.count(a, b);
        (inside, all, all > 0 && 2 * inside >= all)
    }

    /// Whether leaf `cell` of `tree` is kept as a face ([`Silhouette::coverage`]).
    pub fn keeps(&self, tree: &Quadtree, cell: &Cell) -> bool {
        self.coverage(tree, cell).2
    }

    /// What leaf `cell` costs in pixels on the wrong side of the outline: those outside if it
    /// is kept, those inside if not, at [`MISCOVERED_PIXEL_ERROR`] each.
    pub fn miscovered_error(&self, tree: &Quadtree, cell: &Cell) -> f64 {
        let (inside, all, kept) = self.coverage(tree, cell);
        let wrong = if kept { all - inside } else { inside };
        wrong as f64 * MISCOVERED_PIXEL_ERROR
    }

    fn is_inside(&self, x: i64, y: i64) -> bool {
        x >= 0
            && y >= 0
            && (x as usize) < self.width
            && (y as usize) < self.height
            && self.inside[y as usize * self.width + x as usize]
    }

    /// The point of the silhouette's edge (the midpoints of the pixel sides between an inside
    /// and an outside pixel) nearest to `p` within `reach` pixels, if any.
    pub fn nearest_edge(&self, p: Point, reach: f64) -> Option<Point> {
        let r = reach.ceil() as i64;
        let (cx, cy) = (p.x.floor() as i64, p.y.floor() as i64);
        let mut best: Option<(f64, Point)> = None;
        for y in cy - r..=cy + r {
            for x in cx - r..=cx + r {
                if !self.is_inside(x, y) {
                    continue;
                }
                let centre = Point::new(x as f64 + 0.5, y as f64 + 0.5);
                for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                    if self.is_inside(x + dx, y + dy) || self.off_picture(x + dx, y + dy) {
                        continue;
                    }
                    let q = centre + kurbo::Vec2::new(dx as f64 * 0.5, dy as f64 * 0.5);
                    let d = q.distance(p);
                    if d <= reach && best.is_none_or(|(bd, _)| d < bd) {
                        best = Some((d, q));
                    }
                }
            }
        }
        best.map(|(_, q)| q)
    }

    /// Whether pixel `(x, y)` lies off the picture: the picture's own sides are not part of
    /// the silhouette's edge (the mesh ends there anyway).
    fn off_picture(&self, x: i64, y: i64) -> bool {
        x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height
    }
}

/// The faces of `shape` (one per leaf of `tree`) that `silhouette` keeps, over the points they
/// use, with a point shared by faces that meet only there (two cells touching at a corner)
/// made one point per fan of faces, so that the mesh is manifold. Returns that mesh and, per
/// face, the leaf it is.
pub(crate) fn kept_faces(
    shape: TreeMesh,
    tree: &Quadtree,
    silhouette: &Silhouette,
) -> (TreeMesh, Vec<usize>) {
    let leaves: Vec<usize> = (0..tree.leaves.len())
        .filter(|&i| silhouette.keeps(tree, &tree.leaves[i]))
        .collect();
    let mut faces: Vec<Vec<u32>> = leaves.iter().map(|&i| shape.faces[i].clone()).collect();
    let mut keys = shape.keys;
    let mut positions = shape.positions;
    split_pinched_points(&mut faces, &mut keys, &mut positions);
    // Keep only the points the faces use, in their order.
    let mut new_index: HashMap<u32, u32> = HashMap::new();
    let (mut used_keys, mut used_positions) = (Vec::new(), Vec::new());
    for f in &mut faces {
        for v in f.iter_mut() {
            *v = *new_index.entry(*v).or_insert_with(|| {
                used_keys.push(keys[*v as usize]);
                used_positions.push(positions[*v as usize]);
                used_keys.len() as u32 - 1
            });
        }
    }
    let mesh = TreeMesh {
        keys: used_keys,
        positions: used_positions,
        faces,
    };
    (mesh, leaves)
}

/// Gives each fan of faces around a point its own copy of the point, where faces meet at the
/// point without a chain of edges through it between them.
fn split_pinched_points(
    faces: &mut [Vec<u32>],
    keys: &mut Vec<(u32, u32)>,
    positions: &mut Vec<Point>,
) {
    // Per point, the (face, corner) pairs at it.
    let mut around: HashMap<u32, Vec<(usize, usize)>> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for (c, &v) in face.iter().enumerate() {
            around.entry(v).or_default().push((f, c));
        }
    }
    let mut points: Vec<u32> = around.keys().copied().collect();
    points.sort_unstable();
    for v in points {
        let corners = &around[&v];
        if corners.len() < 2 {
            continue;
        }
        // Faces at v joined where they share an edge from v.
        let mut fans = UnionFind::new(corners.len());
        let mut by_neighbour: HashMap<u32, usize> = HashMap::new();
        for (i, &(f, c)) in corners.iter().enumerate() {
            let n = faces[f].len();
            for u in [faces[f][(c + 1) % n], faces[f][(c + n - 1) % n]] {
                if let Some(&j) = by_neighbour.get(&u) {
                    fans.union(i, j);
                } else {
                    by_neighbour.insert(u, i);
                }
            }
        }
        let mut copy_of_fan: HashMap<usize, u32> = HashMap::new();
        for (i, &(f, c)) in corners.iter().enumerate() {
            let fan = fans.find(i);
            let first = copy_of_fan.is_empty();
            let index = *copy_of_fan.entry(fan).or_insert_with(|| {
                if first {
                    v
                } else {
                    keys.push(keys[v as usize]);
                    positions.push(positions[v as usize]);
                    positions.len() as u32 - 1
                }
            });
            faces[f][c] = index;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::GradientMesh;
    use crate::ColourSpace;

    /// A picture whose top-left and bottom-right quarters are opaque: of a 2 x 2 grid of
    /// cells the two diagonal ones are kept, and the point where they touch becomes two, so
    /// that the mesh is manifold (it validates).
    #[test]
    fn cells_touching_at_a_corner_get_a_point_each() {
        let (w, h) = (20u32, 20u32);
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let opaque = (x < 10) == (y < 10);
                [0.5, 0.5, 0.5, if opaque { 1.0 } else { 0.0 }]
            })
            .collect();
        let image = RgbaImage {
            width: w,
            height: h,
            pixels,
        };
        let silhouette = Silhouette::of(&image).expect("some pixels are transparent");
        let tree = Quadtree::new(20.0, 20.0, 2, 2);
        let (shape, leaves) = kept_faces(tree.mesh(), &tree, &silhouette);
        assert_eq!(leaves, [0, 3]);
        assert_eq!(shape.faces.len(), 2);
        assert_eq!(shape.positions.len(), 8);
        let centre = Point::new(10.0, 10.0);
        assert_eq!(shape.positions.iter().filter(|&&p| p == centre).count(), 2);
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for p in &shape.positions {
            mesh.add_point(*p, [50.0, 0.0, 0.0]);
        }
        for f in shape.faces {
            mesh.add_face(f);
        }
        crate::validate::validate(&mesh).expect("a manifold mesh");
    }

    /// The nearest point of the edge lies between an inside and an outside pixel, and none is
    /// found beyond the reach.
    #[test]
    fn the_nearest_edge_point_is_between_pixels() {
        let (w, h) = (10u32, 4u32);
        let pixels = (0..w * h)
            .map(|i| [0.0, 0.0, 0.0, if i % w < 6 { 1.0 } else { 0.0 }])
            .collect();
        let image = RgbaImage {
            width: w,
            height: h,
            pixels,
        };
        let s = Silhouette::of(&image).unwrap();
        let q = s.nearest_edge(Point::new(4.2, 2.0), 3.0).unwrap();
        assert_eq!(q.x, 6.0);
        assert!(s.nearest_edge(Point::new(1.0, 2.0), 3.0).is_none());
    }
}
