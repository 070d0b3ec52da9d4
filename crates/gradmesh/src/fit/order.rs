//! The order a vectorised mesh is written in: the same mesh, its faces along a Hilbert curve
//! over the picture and its points numbered as the faces first use them, so that the file's
//! face lists hold small runs of similar numbers and neighbouring lines share digits, which
//! gzip finds.

use crate::mesh::GradientMesh;

/// Bits of each coordinate on the Hilbert curve.
const CURVE_BITS: u32 = 16;

/// The distance along a Hilbert curve over a `2^CURVE_BITS` square of the cell `(x, y)`.
fn hilbert_distance(mut x: u32, mut y: u32) -> u64 {
    let last = (1u32 << CURVE_BITS) - 1;
    let mut distance = 0u64;
    let mut s = 1u32 << (CURVE_BITS - 1);
    while s > 0 {
        let rx = u32::from(x & s != 0);
        let ry = u32::from(y & s != 0);
        distance += u64::from(s) * u64::from(s) * u64::from((3 * rx) ^ ry);
        if ry == 0 {
            if rx == 1 {
                x = last - x;
                y = last - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        s >>= 1;
    }
    distance
}

/// Where the centre of face `face` lies on the Hilbert curve over the `width` x `height`
/// picture.
fn face_distance(mesh: &GradientMesh, face: &[u32], width: f64, height: f64) -> u64 {
    let n = face.len().max(1) as f64;
    let (sx, sy) = face.iter().fold((0.0, 0.0), |(sx, sy), &p| {
        let q = mesh.points[p as usize].position;
        (sx + q.x, sy + q.y)
    });
    let cell = |v: f64, side: f64| {
        let top = f64::from((1u32 << CURVE_BITS) - 1);
        ((v / n / side.max(1e-9)) * top).clamp(0.0, top) as u32
    };
    hilbert_distance(cell(sx, width), cell(sy, height))
}

/// The points' new numbers: in the order `faces` first use them, unused points last.
fn first_use_numbers(points: usize, faces: &[Vec<u32>]) -> Vec<u32> {
    let mut number = vec![u32::MAX; points];
    let mut next = 0u32;
    let all = faces.iter().flatten().copied().chain(0..points as u32);
    for p in all {
        if number[p as usize] == u32::MAX {
            number[p as usize] = next;
            next += 1;
        }
    }
    number
}

/// Renumbers `mesh` for a small gzipped file without changing the mesh: faces sorted along a
/// Hilbert curve over the `width` x `height` picture by their centres, points numbered in the
/// order the faces first use them, each face's loop starting at its smallest number (the same
/// loop, same winding). The mesh must have no handles, tags, wedge colours or edits (a
/// vectorised mesh has none); one that has any is left as it is.
pub(crate) fn order_for_output(mesh: &mut GradientMesh, width: f64, height: f64) {
    let plain = mesh.handles.is_empty()
        && mesh.edges.is_empty()
        && mesh.wedges.is_empty()
        && mesh.edits.is_empty();
    if !plain {
        return;
    }
    let mut faces = std::mem::take(&mut mesh.faces);
    faces.sort_by_cached_key(|f| face_distance(mesh, f, width, height));
    let number = first_use_numbers(mesh.points.len(), &faces);
    for face in &mut faces {
        for p in face.iter_mut() {
            *p = number[*p as usize];
        }
        let smallest = (0..face.len()).min_by_key(|&i| face[i]).unwrap_or(0);
        face.rotate_left(smallest);
    }
    let mut points = vec![None; mesh.points.len()];
    for (old, point) in std::mem::take(&mut mesh.points).into_iter().enumerate() {
        points[number[old] as usize] = Some(point);
    }
    mesh.points = points.into_iter().flatten().collect();
    mesh.faces = faces;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::ColourSpace;
    use crate::fit::quadtree::Quadtree;
    use crate::mesh::Document;
    use crate::render::{render_document_into, RenderOptions, View};
    use std::io::Write;

    /// The curve visits the four quarters of the square in its order (lower left, upper left,
    /// upper right, lower right in y-up terms) and each cell once.
    #[test]
    fn hilbert_distances_follow_the_curve() {
        let half = 1u32 << (CURVE_BITS - 1);
        let quarter = u64::from(half) * u64::from(half);
        assert_eq!(hilbert_distance(0, 0), 0);
        assert_eq!(hilbert_distance(0, half) / quarter, 1);
        assert_eq!(hilbert_distance(half, half) / quarter, 2);
        assert_eq!(hilbert_distance(half, 0) / quarter, 3);
        let corners: std::collections::HashSet<u64> = (0..4)
            .flat_map(|x| (0..4).map(move |y| hilbert_distance(x << 14, y << 14)))
            .collect();
        assert_eq!(corners.len(), 16);
    }

    /// A quadtree mesh of about 400 points with uneven splits, its points moved and coloured.
    fn split_mesh() -> GradientMesh {
        let mut tree = Quadtree::new(160.0, 120.0, 4, 3);
        for round in 0..5 {
            let which: Vec<usize> = (0..tree.leaves.len())
                .filter(|i| (i * 7 + round) % 5 < 2)
                .collect();
            tree.split(&which);
        }
        let shape = tree.mesh();
        let mut mesh = GradientMesh::new(ColourSpace::Lab);
        for (i, p) in shape.positions.iter().enumerate() {
            let t = i as f64;
            let inside = p.x > 0.0 && p.y > 0.0 && p.x < 160.0 && p.y < 120.0;
            let wobble = if inside { 0.3 * (t * 0.9).sin() } else { 0.0 };
            let colour = [
                50.0 + 20.0 * (t * 0.3).sin(),
                10.0 * (t * 0.7).cos(),
                t % 17.0,
            ];
            mesh.add_point(*p + kurbo::Vec2::new(wobble, wobble), colour);
        }
        for f in shape.faces {
            mesh.add_face(f);
        }
        mesh
    }

    fn render(mesh: &GradientMesh) -> Vec<u8> {
        let document = Document::new(vec![mesh.clone()]);
        let opts = RenderOptions::new(160, 120, View::new(0.0, 0.0, 160.0, 120.0));
        let mut out = vec![0u8; 4 * 160 * 120];
        render_document_into(&document, &opts, &mut out).unwrap();
        out
    }

    fn gzip_bytes(mesh: &GradientMesh) -> usize {
        let document = Document::new(vec![mesh.clone()]);
        let text = crate::formats::json::write_document(&document);
        let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        encoder.write_all(text.as_bytes()).unwrap();
        encoder.finish().unwrap().len()
    }

    /// The ordered mesh is the same mesh: the same points, faces as the same loops, the same
    /// render (to one 8-bit level in under a thousandth of the channels, where sums over a
    /// face's points run in another order); its gzipped file is smaller.
    #[test]
    fn ordered_mesh_renders_the_same_in_fewer_bytes() {
        let mesh = split_mesh();
        assert!(mesh.points.len() > 300, "{} points", mesh.points.len());
        let mut ordered = mesh.clone();
        order_for_output(&mut ordered, 160.0, 120.0);
        crate::validate::validate(&ordered).unwrap();
        let loops = |m: &GradientMesh| {
            let mut loops: Vec<Vec<(u64, u64)>> = m
                .faces
                .iter()
                .map(|f| {
                    let at = |p: &u32| {
                        let q = m.points[*p as usize].position;
                        (q.x.to_bits(), q.y.to_bits())
                    };
                    let mut l: Vec<(u64, u64)> = f.iter().map(at).collect();
                    let first = (0..l.len()).min_by_key(|&i| l[i]).unwrap();
                    l.rotate_left(first);
                    l
                })
                .collect();
            loops.sort();
            loops
        };
        assert_eq!(loops(&mesh), loops(&ordered));
        assert_ne!(mesh.faces, ordered.faces);
        let (a, b) = (render(&mesh), render(&ordered));
        let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        let most = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max();
        assert!(
            most <= Some(1) && differ * 1000 < a.len(),
            "{differ} bytes differ, by at most {most:?}"
        );
        let (before, after) = (gzip_bytes(&mesh), gzip_bytes(&ordered));
        assert!(after < before, "ordered {after} bytes, unordered {before}");
    }
}
