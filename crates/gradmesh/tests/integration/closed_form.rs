//! Closed-form checks of the refinement: the regular case is a uniform bicubic B-spline,
//! creases are cubic B-spline curves, discontinuous edges separate their sides, and the Euler
//! characteristic is kept.

use gradmesh::Refinement;
use gradmesh::Topology;
use gradmesh::{ColourSpace, EdgeKind, GradientMesh};
use gradmesh::{WedgeOverride, SHARPNESS_INFINITE};
use kurbo::{Point, Vec2};

/// A grid of `w` x `h` square cells of side `cell`, with colours from `colour(i, j)`.
fn grid(w: u32, h: u32, cell: f64, colour: impl Fn(u32, u32) -> [f64; 3]) -> GradientMesh {
    let mut mesh = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=h {
        for i in 0..=w {
            mesh.add_point(Point::new(cell * i as f64, cell * j as f64), colour(i, j));
        }
    }
    for j in 0..h {
        for i in 0..w {
            let v = j * (w + 1) + i;
            mesh.add_face(vec![v, v + 1, v + w + 2, v + w + 1]);
        }
    }
    mesh
}

/// A deterministic pseudo-random colour.
fn hash_colour(i: u32, j: u32) -> [f64; 3] {
    let mut x = (i.wrapping_mul(73_856_093) ^ j.wrapping_mul(19_349_663)) as u64;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % 10_000) as f64 / 10_000.0
    };
    [100.0 * next(), 160.0 * next() - 80.0, 160.0 * next() - 80.0]
}

/// Uniform cubic B-spline basis at parameter `t` in 0..1.
fn bspline_basis(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        s * s * s / 6.0,
        (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t * t * t / 6.0,
    ]
}

#[test]
fn default_handles_give_the_uniform_three_way_split() {
    let cell = 3.0;
    let mesh = grid(4, 3, cell, hash_colour);
    let (r, _) = Refinement::new(&mesh, 1).unwrap();
    let data = r.evaluate();
    // Every level-1 point lies on the lattice of spacing 1, and the lattice is complete.
    let level1 = &data.levels[1];
    let mut seen = std::collections::HashSet::new();
    for d in level1 {
        let (x, y) = (d.position[0], d.position[1]);
        assert!(
            (x - x.round()).abs() < 1e-12 && (y - y.round()).abs() < 1e-12,
            "{d:?}"
        );
        seen.insert((x.round() as i64, y.round() as i64));
    }
    assert_eq!(seen.len(), 13 * 10);
    assert_eq!(level1.len(), 13 * 10);
    assert!(r.topology(1).is_all_quads());
}

#[test]
fn regular_grid_limit_is_the_uniform_bicubic_bspline_of_level_1() {
    // With default handles the level-1 net is the lattice of spacing 1, so the limit position
    // of a point is its own parameter in lattice units; compare limit colours with the tensor
    // B-spline of the level-1 colour net, away from the boundary.
    let (w, h) = (4u32, 4u32);
    let mesh = grid(w, h, 3.0, hash_colour);
    let depth = 3;
    let (mut r, data) = {
        let (r, _) = Refinement::new(&mesh, depth).unwrap();
        let d = r.evaluate();
        (r, d)
    };
    let n1 = (3 * w + 1) as usize;
    let mut net = vec![[0.0f64; 3]; n1 * n1];
    for d in &data.levels[1] {
        let (i, j) = (
            d.position[0].round() as usize,
            d.position[1].round() as usize,
        );
        net[j * n1 + i] = d.colour;
    }
    let limit = r.limit(&data, depth);
    let mut checked = 0;
    for d in &limit {
        let (u, v) = (d.position[0], d.position[1]);
        // Stay two lattice units inside, where no boundary rule reaches.
        if u < 2.0 || v < 2.0 || u > (n1 - 3) as f64 || v > (n1 - 3) as f64 {
            continue;
        }
        let (iu, iv) = (u.floor() as usize, v.floor() as usize);
        let (bu, bv) = (bspline_basis(u - iu as f64), bspline_basis(v - iv as f64));
        let mut expect = [0.0; 3];
        for (a, wa) in bu.iter().enumerate() {
            for (b, wb) in bv.iter().enumerate() {
                let c = net[(iv + b - 1) * n1 + (iu + a - 1)];
                for k in 0..3 {
                    expect[k] += wa * wb * c[k];
                }
            }
        }
        for k in 0..3 {
            assert!(
                (d.to_array()[2 + k] - expect[k]).abs() < 1e-9,
                "at ({u}, {v}) channel {k}: {} vs {}",
                d.to_array()[2 + k],
                expect[k]
            );
        }
        checked += 1;
    }
    assert!(checked > 100, "{checked}");
}

/// The vertices of the crease (interior infinitely sharp edges) of a level, in order along it.
fn crease_polygon(topology: &Topology, sharpness: &[f64]) -> Vec<u32> {
    let crease: Vec<usize> = (0..topology.edge_count())
        .filter(|&e| !topology.is_boundary_edge(e) && sharpness[e] >= SHARPNESS_INFINITE)
        .collect();
    let mut degree = std::collections::HashMap::new();
    for &e in &crease {
        for v in topology.edge_vertices(e) {
            *degree.entry(v).or_insert(0) += 1;
        }
    }
    let start = *degree
        .iter()
        .filter(|(_, &d)| d == 1)
        .map(|(v, _)| v)
        .min()
        .unwrap();
    let mut polygon = vec![start];
    let mut used = vec![false; crease.len()];
    loop {
        let last = *polygon.last().unwrap();
        let Some(k) = (0..crease.len())
            .find(|&k| !used[k] && topology.edge_vertices(crease[k]).contains(&last))
        else {
            break;
        };
        used[k] = true;
        polygon.push(topology.other_vertex(crease[k], last));
    }
    polygon
}

#[test]
fn a_crease_is_the_cubic_bspline_curve_of_its_refined_points() {
    // A 4x3 grid creased along the interior row y = 1 from boundary to boundary, with handles
    // that bend the geometry so the curve is not trivially straight.
    let mut mesh = grid(4, 3, 10.0, hash_colour);
    for i in 0..4u32 {
        let (a, b) = (5 + i, 6 + i);
        mesh.set_edge(a, b, EdgeKind::Crease, None);
        mesh.set_handle(a, b, Vec2::new(3.0, 2.0 + i as f64));
        mesh.set_handle(b, a, Vec2::new(-3.5, -1.0));
    }
    let depth = 4;
    let (mut r, _) = Refinement::new(&mesh, depth).unwrap();
    let data = r.evaluate();
    let limit = r.limit(&data, depth);

    // The level-1 crease polygon, refined as a curve with fixed ends (the ends meet the
    // boundary, where three sharp edges make a corner): midpoints, and (1, 6, 1) / 8.
    let poly1 = crease_polygon(r.topology(1), &r.level(1).edge_sharpness);
    assert_eq!(poly1.len(), 13);
    let mut curve: Vec<[f64; 6]> = poly1
        .iter()
        .map(|&v| data.levels[1][v as usize].to_array())
        .collect();
    let mix = |a: &[f64; 6], b: &[f64; 6], c: &[f64; 6], w: [f64; 3]| {
        std::array::from_fn(|k| w[0] * a[k] + w[1] * b[k] + w[2] * c[k])
    };
    for level in 2..=depth {
        let mut next = Vec::with_capacity(2 * curve.len() - 1);
        for i in 0..curve.len() {
            let v = if i == 0 || i + 1 == curve.len() {
                curve[i]
            } else {
                mix(
                    &curve[i - 1],
                    &curve[i],
                    &curve[i + 1],
                    [0.125, 0.75, 0.125],
                )
            };
            next.push(v);
            if i + 1 < curve.len() {
                next.push(mix(&curve[i], &curve[i + 1], &curve[i], [0.5, 0.5, 0.0]));
            }
        }
        curve = next;
        let poly = crease_polygon(r.topology(level), &r.level(level).edge_sharpness);
        assert_eq!(poly.len(), curve.len());
        for (k, &v) in poly.iter().enumerate() {
            let ours = data.levels[level][v as usize];
            for c in 0..6 {
                assert!(
                    (ours.to_array()[c] - curve[k][c]).abs() < 1e-9,
                    "level {level} point {k}"
                );
            }
        }
    }
    // Limit points on the crease: the B-spline curve point (1, 4, 1) / 6.
    let poly = crease_polygon(r.topology(depth), &r.level(depth).edge_sharpness);
    for i in 1..poly.len() - 1 {
        let expect: [f64; 6] = mix(
            &curve[i - 1],
            &curve[i],
            &curve[i + 1],
            [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
        );
        let got = limit[poly[i] as usize];
        for c in 0..6 {
            assert!((got.to_array()[c] - expect[c]).abs() < 1e-9);
        }
    }
}

/// Connected components of the faces of a topology: the component of each vertex.
fn vertex_components(t: &Topology) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..t.vertex_count()).collect();
    fn find(p: &mut [usize], x: usize) -> usize {
        let mut x = x;
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for f in 0..t.face_count() {
        let fv = t.face_vertices(f);
        for w in fv.windows(2) {
            let (a, b) = (
                find(&mut parent, w[0] as usize),
                find(&mut parent, w[1] as usize),
            );
            parent[a] = b;
        }
    }
    (0..t.vertex_count())
        .map(|v| find(&mut parent, v))
        .collect()
}

#[test]
fn a_discontinuous_edge_separates_its_sides() {
    // A 4x3 grid cut from top to bottom along x = 2 (points 2, 7, 12, 17).
    let mut mesh = grid(4, 3, 10.0, hash_colour);
    let line = [2u32, 7, 12, 17];
    for w in line.windows(2) {
        mesh.set_edge(w[0], w[1], EdgeKind::Discontinuous, None);
    }
    // The right side of the cut (faces with i = 2) gets its own colours.
    let right_face = |j: u32| j * 4 + 2;
    for (j, &p) in line.iter().enumerate() {
        let face = right_face((j as u32).min(2));
        mesh.wedges.push(WedgeOverride {
            point: p,
            face,
            colour: [50.0, 60.0, -20.0 + j as f64],
            colour_text: None,
            opacity: None,
            handles: Default::default(),
        });
    }
    let depth = 3;
    let (r, _) = Refinement::new(&mesh, depth).unwrap();
    let before = r.evaluate();

    // Recolour the whole right side: the right-hand points and the right wedges.
    let mut recoloured = mesh.clone();
    for (p, point) in recoloured.points.iter_mut().enumerate() {
        if p as u32 % 5 > 2 {
            point.colour = [10.0, -5.0, 5.0];
        }
    }
    for w in &mut recoloured.wedges {
        w.colour = [90.0, 0.0, 0.0];
    }
    let (r2, _) = Refinement::new(&recoloured, depth).unwrap();
    let after = r2.evaluate();

    for k in 1..=depth {
        let t = r.topology(k);
        let comp = vertex_components(t);
        // The component of vertex point 0 (top-left control point) is the left side.
        let left = comp[0];
        let mut changed_right = 0;
        for v in 0..t.vertex_count() {
            if comp[v] == left {
                assert_eq!(
                    before.levels[k][v], after.levels[k][v],
                    "level {k} vertex {v}"
                );
            } else if before.levels[k][v] != after.levels[k][v] {
                changed_right += 1;
            }
        }
        assert!(changed_right > 0);
        assert_eq!(
            comp.iter().collect::<std::collections::HashSet<_>>().len(),
            2,
            "the cut splits the mesh in two"
        );
    }
}

#[test]
fn refinement_keeps_the_euler_characteristic() {
    let mut mesh = grid(3, 3, 1.0, hash_colour);
    // A hole: drop the middle face.
    mesh.faces.remove(4);
    mesh.set_edge(0, 1, EdgeKind::Crease, Some(2.5));
    let (r, _) = Refinement::new(&mesh, 4).unwrap();
    let chi = r.topology(0).euler_characteristic();
    assert_eq!(chi, 0, "an annulus");
    for k in 1..=4 {
        assert_eq!(r.topology(k).euler_characteristic(), chi, "level {k}");
    }
}
