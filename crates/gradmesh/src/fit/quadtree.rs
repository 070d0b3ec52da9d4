//! The vectoriser's topology: a grid of cells over the picture, each cell split into four where
//! the fit is worst. Every leaf cell is one face whose corners are all the points on its
//! sides, so a large cell beside split ones is an n-gon and the points between them have
//! valence three: free topology that the scheme refines as it is, with no T-junction rule.

use std::collections::{BTreeSet, HashMap, HashSet};

use kurbo::Point;

/// A root cell's side in integer units: cells split down to one unit.
const ROOT_SIDE: u32 = 1 << 16;

/// A point of the tree, in integer units (`ROOT_SIDE` per root cell along each axis).
pub(crate) type Key = (u32, u32);

/// One leaf: its top-left corner and side, in integer units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Cell {
    x: u32,
    y: u32,
    size: u32,
}

impl Cell {
    /// Corners and side midpoints and centre of the four children.
    fn child_keys(&self) -> [Key; 9] {
        let h = self.size / 2;
        let mut k = [(0, 0); 9];
        for j in 0..3 {
            for i in 0..3 {
                k[3 * j + i] = (self.x + i as u32 * h, self.y + j as u32 * h);
            }
        }
        k
    }

    fn children(&self) -> [Cell; 4] {
        let h = self.size / 2;
        [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(i, j)| Cell {
            x: self.x + i * h,
            y: self.y + j * h,
            size: h,
        })
    }
}

/// A picture of `width` x `height` pixels covered by `cols` x `rows` root cells, split.
#[derive(Clone, Debug)]
pub(crate) struct Quadtree {
    width: f64,
    height: f64,
    cols: u32,
    rows: u32,
    /// The faces of the mesh, in order.
    pub leaves: Vec<Cell>,
}

/// A tree's mesh: faces (one per leaf, in order) over points named by their keys.
pub(crate) struct TreeMesh {
    pub keys: Vec<Key>,
    pub positions: Vec<Point>,
    pub faces: Vec<Vec<u32>>,
}

impl Quadtree {
    /// `cols` x `rows` cells over the picture.
    pub fn new(width: f64, height: f64, cols: u32, rows: u32) -> Quadtree {
        let mut leaves = Vec::with_capacity((cols * rows) as usize);
        for j in 0..rows {
            for i in 0..cols {
                leaves.push(Cell {
                    x: i * ROOT_SIDE,
                    y: j * ROOT_SIDE,
                    size: ROOT_SIDE,
                });
            }
        }
        Quadtree {
            width,
            height,
            cols,
            rows,
            leaves,
        }
    }

    /// Where a key lies in the picture, in pixels.
    pub fn position(&self, (x, y): Key) -> Point {
        Point::new(
            x as f64 * self.width / (self.cols as f64 * ROOT_SIDE as f64),
            y as f64 * self.height / (self.rows as f64 * ROOT_SIDE as f64),
        )
    }

    /// A leaf's top-left and bottom-right corners, in pixels.
    pub fn cell_corners(&self, c: &Cell) -> (Point, Point) {
        (
            self.position((c.x, c.y)),
            self.position((c.x + c.size, c.y + c.size)),
        )
    }

    /// The smaller side of a leaf, in pixels.
    pub fn side_px(&self, c: &Cell) -> f64 {
        let f = c.size as f64 / ROOT_SIDE as f64;
        (f * self.width / self.cols as f64).min(f * self.height / self.rows as f64)
    }

    /// Whether leaf `c` can be split into cells at least `min_px` pixels across.
    pub fn can_split(&self, c: &Cell, min_px: f64) -> bool {
        c.size >= 2 && self.side_px(c) >= 2.0 * min_px
    }

    /// The points splitting leaf `c` adds to those in `present`.
    pub fn new_points(c: &Cell, present: &HashSet<Key>) -> Vec<Key> {
        c.child_keys()
            .into_iter()
            .filter(|k| !present.contains(k))
            .collect()
    }

    /// Splits the leaves `which` (indices into [`Quadtree::leaves`]) into four each.
    pub fn split(&mut self, which: &[usize]) {
        let mut chosen = vec![false; self.leaves.len()];
        for &i in which {
            chosen[i] = true;
        }
        let mut leaves = Vec::with_capacity(self.leaves.len() + 3 * which.len());
        for (cell, split) in self.leaves.iter().zip(chosen) {
            if split {
                leaves.extend(cell.children());
            } else {
                leaves.push(*cell);
            }
        }
        self.leaves = leaves;
    }

    /// The keys of every leaf corner.
    pub fn corner_keys(&self) -> HashSet<Key> {
        self.leaves
            .iter()
            .flat_map(|c| {
                let s = c.size;
                [
                    (c.x, c.y),
                    (c.x + s, c.y),
                    (c.x + s, c.y + s),
                    (c.x, c.y + s),
                ]
            })
            .collect()
    }

    /// The mesh: one face per leaf, running along its top side left to right, down its right
    /// side, back along its bottom and up its left side, through every point on them.
    pub fn mesh(&self) -> TreeMesh {
        let mut index: HashMap<Key, u32> = HashMap::new();
        let mut keys = Vec::new();
        for c in &self.leaves {
            let s = c.size;
            for k in [
                (c.x, c.y),
                (c.x + s, c.y),
                (c.x + s, c.y + s),
                (c.x, c.y + s),
            ] {
                index.entry(k).or_insert_with(|| {
                    keys.push(k);
                    keys.len() as u32 - 1
                });
            }
        }
        // Points by row (y, x) and by column (x, y), for the points inside each side.
        let by_row: BTreeSet<(u32, u32)> = keys.iter().map(|&(x, y)| (y, x)).collect();
        let by_col: BTreeSet<(u32, u32)> = keys.iter().copied().collect();
        let faces = self
            .leaves
            .iter()
            .map(|c| {
                let (x0, y0, x1, y1) = (c.x, c.y, c.x + c.size, c.y + c.size);
                let id = |k: Key| index[&k];
                let mut face = vec![id((x0, y0))];
                face.extend(
                    by_row
                        .range((y0, x0 + 1)..(y0, x1))
                        .map(|&(y, x)| id((x, y))),
                );
                face.push(id((x1, y0)));
                face.extend(by_col.range((x1, y0 + 1)..(x1, y1)).map(|&k| id(k)));
                face.push(id((x1, y1)));
                face.extend(
                    by_row
                        .range((y1, x0 + 1)..(y1, x1))
                        .rev()
                        .map(|&(y, x)| id((x, y))),
                );
                face.push(id((x0, y1)));
                face.extend(by_col.range((x0, y0 + 1)..(x0, y1)).rev().map(|&k| id(k)));
                face
            })
            .collect();
        let positions = keys.iter().map(|&k| self.position(k)).collect();
        TreeMesh {
            keys,
            positions,
            faces,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A split cell beside an unsplit one makes the unsplit one a pentagon whose extra corner
    /// is the split side's midpoint; split costs count shared points once.
    #[test]
    fn split_cells_make_n_gons_beside_them() {
        let mut tree = Quadtree::new(200.0, 100.0, 2, 1);
        let present = tree.corner_keys();
        assert_eq!(present.len(), 6);
        assert_eq!(Quadtree::new_points(&tree.leaves[0], &present).len(), 5);
        tree.split(&[0]);
        let mesh = tree.mesh();
        assert_eq!(mesh.keys.len(), 11);
        assert_eq!(mesh.faces.len(), 5);
        let last = mesh.faces.last().unwrap();
        assert_eq!(last.len(), 5);
        let midpoint = mesh.positions[last[4] as usize];
        assert_eq!(midpoint, Point::new(100.0, 50.0));
        assert!(mesh.faces[..4].iter().all(|f| f.len() == 4));
    }
}
