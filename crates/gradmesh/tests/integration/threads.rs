//! Refinement and OBJ output do not depend on the number of threads: computed in a
//! one-thread pool, in a four-thread pool and in the default pool, they are equal bit for bit.
//! Also: the last level's data computed without the stencil table (`refine_data`, used by
//! `gradmesh refine`) equals applying the table.

use gradmesh::formats::{self, obj};
use gradmesh::internals::catmull_clark;
use gradmesh::Refinement;
use gradmesh::VertexData;
use gradmesh::{ColourSpace, EdgeKind, GradientMesh};
use kurbo::{Point, Vec2};

/// Every level's data (as bits) and the OBJ of the deepest level.
fn run(mesh: &GradientMesh, depth: usize) -> (Vec<Vec<[u64; 6]>>, String) {
    let (r, _) = Refinement::new(mesh, depth).unwrap();
    let data = r.evaluate();
    let bits = data
        .levels
        .iter()
        .map(|l| l.iter().map(|d| d.to_array().map(f64::to_bits)).collect())
        .collect();
    let obj = obj::write_refined_obj(&[(None, r.topology(depth), &data.levels[depth])]);
    (bits, obj)
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

fn assert_thread_independent(mesh: &GradientMesh, depth: usize) {
    let default = run(mesh, depth);
    let one = in_pool(1, || run(mesh, depth));
    assert!(one.0 == default.0, "level data differ with one thread");
    assert!(one.1 == default.1, "OBJ output differs with one thread");
    let four = in_pool(4, || run(mesh, depth));
    assert!(four.0 == default.0, "level data differ with four threads");
    assert!(four.1 == default.1, "OBJ output differs with four threads");
}

/// A jittered 60 x 50 grid with curved handles, a crease and a discontinuous edge: large
/// enough that every parallel path (stencil building and application, OBJ blocks) splits.
fn generated() -> GradientMesh {
    let (w, h) = (60u32, 50u32);
    let mut m = GradientMesh::new(ColourSpace::Lab);
    for j in 0..=h {
        for i in 0..=w {
            let jitter = ((i * 7 + j * 13) % 10) as f64 * 0.03;
            m.add_point(
                Point::new(i as f64 + jitter, j as f64 - jitter),
                [
                    (i % 100) as f64,
                    (j % 50) as f64 - 25.0,
                    (i * j % 37) as f64,
                ],
            );
        }
    }
    for j in 0..h {
        for i in 0..w {
            let v = j * (w + 1) + i;
            let (a, b, c, d) = (v, v + 1, v + w + 2, v + w + 1);
            if (i + j) % 5 == 0 {
                m.add_face(vec![a, b, c]);
                m.add_face(vec![a, c, d]);
            } else {
                m.add_face(vec![a, b, c, d]);
            }
        }
    }
    m.set_handle(0, 1, Vec2::new(0.3, 0.1));
    let row = w + 1;
    m.set_edge(5 * row + 5, 5 * row + 6, EdgeKind::Crease, Some(1.5));
    m.set_edge(10 * row + 10, 10 * row + 11, EdgeKind::Discontinuous, None);
    m.set_edge(10 * row + 11, 10 * row + 12, EdgeKind::Discontinuous, None);
    m
}

#[test]
fn generated_mesh_is_thread_independent() {
    assert_thread_independent(&generated(), 3);
}

#[test]
fn real_file_is_thread_independent() {
    let doc = formats::read_path(&crate::realdata::path("Glasses.off")).unwrap();
    for mesh in &doc.layers {
        assert_thread_independent(mesh, 4);
    }
}

#[test]
fn refine_data_equals_applying_the_stencils() {
    let mesh = generated();
    let (r, _) = Refinement::new(&mesh, 3).unwrap();
    let data = r.evaluate();
    for k in 1..3 {
        let bits = |d: &[VertexData]| {
            d.iter()
                .map(|x| x.to_array().map(f64::to_bits))
                .collect::<Vec<_>>()
        };
        let direct = in_pool(1, || {
            catmull_clark::refine_data(r.level(k), &data.levels[k])
        });
        assert!(
            bits(&direct) == bits(&data.levels[k + 1]),
            "level {}",
            k + 1
        );
        let direct = catmull_clark::refine_data(r.level(k), &data.levels[k]);
        assert!(
            bits(&direct) == bits(&data.levels[k + 1]),
            "level {}",
            k + 1
        );
    }
}
