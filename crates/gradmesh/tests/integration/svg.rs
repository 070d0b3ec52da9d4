//! SVG mesh gradients from real files: the W3C (WPT) tests and the Inkscape samples in
//! `../shared/realdata/meshgradient/`. Patch counts, corner colours and outlines are checked
//! against values read from the SVG text; each file is converted into the scheme and
//! rendered, and the corners of the mesh's outline must show their stop colours.

use std::fs;

use gradmesh::formats::{self, svg};
use gradmesh::render::{render_document, RenderOptions, View};
use gradmesh::{Document, Limits};
use kurbo::{ParamCurve, Point, Rect, Shape};

use crate::realdata;

/// What one shape filled with a mesh gradient must hold.
struct Fill {
    gradient: &'static str,
    rows: usize,
    columns: usize,
    /// The corner colours, row by row, `(rows + 1) * (columns + 1)` of them.
    colours: &'static [&'static str],
    /// The bounding box of the shape's outline.
    clip: [f64; 4],
}

/// What a file must hold: its view box and its fills in paint order.
struct Expected {
    file: &'static str,
    view: [f64; 4],
    fills: &'static [Fill],
}

const B: &str = "#0000ff";
const G: &str = "#00ff00";
const Y: &str = "#ffff00";
const R: &str = "#ff0000";
const WPT_VIEW: [f64; 4] = [0.0, 0.0, 480.0, 360.0];
const SAMPLE_VIEW: [f64; 4] = [0.0, 0.0, 600.00005, 399.99998];
const LEFT: [f64; 4] = [20.0, 140.0, 220.0, 340.0];
const RIGHT: [f64; 4] = [260.0, 140.0, 460.0, 340.0];
/// One patch: blue, green, (second row) green, yellow.
const ONE: &[&str] = &[B, G, G, Y];
/// Two by two patches (basic-003, -004, complex-001).
const FOUR: &[&str] = &[B, G, Y, G, Y, B, Y, B, G];
const CHECKER: &[&str] = &[B, G, B, G, G, B, G, B, B, G, B, G, G, B, G, B];
const SAMPLE_RECT: Fill = Fill {
    gradient: "meshGradient5889",
    rows: 1,
    columns: 1,
    colours: &[R, G, Y, B],
    clip: [300.00003, 99.999985, 500.00003, 299.999985],
};
const SAMPLE_PATH: Fill = Fill {
    gradient: "meshGradient6354",
    rows: 1,
    columns: 1,
    colours: &["#17280b", "#d45500", "#d4ff2a", "#abc837"],
    clip: [98.056801, 81.427312, 333.777151, 355.15692],
};

const FILES: &[Expected] = &[
    Expected {
        file: "wpt/meshgradient-basic-001.svg",
        view: WPT_VIEW,
        fills: &[
            Fill {
                gradient: "LinearMesh",
                rows: 1,
                columns: 1,
                colours: ONE,
                clip: LEFT,
            },
            Fill {
                gradient: "BezierMesh",
                rows: 1,
                columns: 1,
                colours: ONE,
                clip: RIGHT,
            },
        ],
    },
    Expected {
        file: "wpt/meshgradient-basic-002.svg",
        view: WPT_VIEW,
        fills: &[
            Fill {
                gradient: "LinearMesh",
                rows: 1,
                columns: 1,
                colours: ONE,
                clip: LEFT,
            },
            Fill {
                gradient: "BezierMesh",
                rows: 1,
                columns: 1,
                colours: ONE,
                clip: RIGHT,
            },
        ],
    },
    Expected {
        file: "wpt/meshgradient-basic-003.svg",
        view: WPT_VIEW,
        fills: &[
            Fill {
                gradient: "LinearMesh",
                rows: 2,
                columns: 2,
                colours: FOUR,
                clip: LEFT,
            },
            Fill {
                gradient: "BezierMesh",
                rows: 2,
                columns: 2,
                colours: FOUR,
                clip: RIGHT,
            },
        ],
    },
    Expected {
        file: "wpt/meshgradient-basic-004.svg",
        view: WPT_VIEW,
        fills: &[
            Fill {
                gradient: "LinearMesh",
                rows: 2,
                columns: 2,
                colours: FOUR,
                clip: LEFT,
            },
            Fill {
                gradient: "BezierMesh",
                rows: 2,
                columns: 2,
                colours: FOUR,
                clip: RIGHT,
            },
        ],
    },
    Expected {
        file: "wpt/meshgradient-basic-005.svg",
        view: WPT_VIEW,
        fills: &[Fill {
            gradient: "StarMesh",
            rows: 2,
            columns: 10,
            colours: &[
                B, B, B, B, B, B, B, B, B, B, B, G, G, G, G, G, G, G, G, G, G, G, Y, Y, Y, Y, Y, Y,
                Y, Y, Y, Y, Y,
            ],
            clip: [135.3837, 140.0, 344.616, 338.992],
        }],
    },
    Expected {
        file: "wpt/meshgradient-bicubic-001.svg",
        view: WPT_VIEW,
        fills: &[
            Fill {
                gradient: "CheckerBoardCoons",
                rows: 3,
                columns: 3,
                colours: CHECKER,
                clip: LEFT,
            },
            Fill {
                gradient: "CheckerBoardBicubic",
                rows: 3,
                columns: 3,
                colours: CHECKER,
                clip: RIGHT,
            },
        ],
    },
    Expected {
        file: "wpt/meshgradient-complex-001.svg",
        view: WPT_VIEW,
        fills: &[Fill {
            gradient: "PatchPaintOrder",
            rows: 2,
            columns: 2,
            colours: FOUR,
            clip: [80.0, 110.0, 400.0, 350.0],
        }],
    },
    Expected {
        file: "zectorio-mesh-gradient-js/sample1.svg",
        view: SAMPLE_VIEW,
        fills: &[SAMPLE_RECT],
    },
    Expected {
        file: "zectorio-mesh-gradient-js/sample2.svg",
        view: SAMPLE_VIEW,
        fills: &[SAMPLE_RECT, SAMPLE_PATH],
    },
    Expected {
        file: "zectorio-mesh-gradient-js/sample3.svg",
        view: SAMPLE_VIEW,
        fills: &[
            SAMPLE_RECT,
            SAMPLE_PATH,
            Fill {
                gradient: "meshGradient7143",
                rows: 3,
                columns: 2,
                colours: &[R, B, G, G, R, B, B, G, R, R, B, G],
                clip: [25.0, 24.999969, 225.0, 374.999969],
            },
        ],
    },
    Expected {
        file: "zectorio-mesh-gradient-js/sample4.svg",
        view: [0.0, 0.0, 500.0, 500.0],
        fills: &[Fill {
            gradient: "meshGradient10787",
            rows: 3,
            columns: 2,
            colours: &[
                R, "#c8beb7", R, "#ff6600", "#c8beb7", "#c8beb7", "#c8beb7", "#c8beb7", "#d45500",
                "#008000", "#008000", "#008000",
            ],
            clip: [150.0, 50.0, 350.0, 450.0],
        }],
    },
    Expected {
        file: "zectorio-mesh-gradient-js/sample5.svg",
        view: [0.0, 0.0, 744.09448819, 1052.3622047],
        fills: &[Fill {
            gradient: "meshGradient6470",
            rows: 3,
            columns: 2,
            colours: &[
                "#aa4400", R, "#d40000", "#c8beb7", "#c87137", "#d40000", "#ffe680", "#d45500",
                "#c8beb7", "#d45500", "#ffe680", "#504416",
            ],
            clip: [50.337206, 241.714278, 589.484972, 895.368413],
        }],
    },
    Expected {
        file: "zectorio-mesh-gradient-js/sample6.svg",
        view: [0.0, 0.0, 400.0, 400.0],
        fills: &[Fill {
            gradient: "meshGradient13085",
            rows: 3,
            columns: 2,
            colours: &[
                B, "#d45500", "#d45500", "#d45500", "#d45500", "#d45500", "#d45500", "#d45500",
                "#d45500", "#d45500", "#d45500", "#d45500",
            ],
            clip: [100.0, 100.0, 300.0, 300.0],
        }],
    },
];

/// `#rrggbb` as sRGB in 0..1.
fn rgb(hex: &str) -> [f64; 3] {
    let byte = |k: usize| f64::from(u8::from_str_radix(&hex[1 + 2 * k..3 + 2 * k], 16).unwrap());
    [byte(0) / 255.0, byte(1) / 255.0, byte(2) / 255.0]
}

fn read(expected: &Expected) -> svg::SvgScene {
    let text = fs::read_to_string(realdata::meshgradient(expected.file)).unwrap();
    svg::read_svg(&text).unwrap_or_else(|e| panic!("{}: {e}", expected.file))
}

#[test]
fn all_thirteen_files_are_read_as_their_text_says() {
    assert_eq!(FILES.len(), 13);
    for expected in FILES {
        let scene = read(expected);
        let name = expected.file;
        let [x0, y0, x1, y1] = expected.view;
        assert_eq!(scene.view_rect(), Rect::new(x0, y0, x1, y1), "{name}");
        assert_eq!(scene.fills.len(), expected.fills.len(), "{name}");
        for (fill, want) in scene.fills.iter().zip(expected.fills) {
            let grid = &fill.mesh;
            assert_eq!(fill.gradient_id, want.gradient, "{name}");
            assert_eq!(
                (grid.rows, grid.columns),
                (want.rows, want.columns),
                "{name}"
            );
            assert_eq!(grid.corners.len(), want.colours.len(), "{name}");
            for (k, (corner, hex)) in grid.corners.iter().zip(want.colours).enumerate() {
                assert_eq!(
                    corner.colour,
                    rgb(hex),
                    "{name} {}: corner {k}",
                    want.gradient
                );
                assert_eq!(corner.opacity, 1.0, "{name}");
            }
            let bbox = fill.clip.bounding_box();
            let [x0, y0, x1, y1] = want.clip;
            let error = [bbox.x0 - x0, bbox.y0 - y0, bbox.x1 - x1, bbox.y1 - y1];
            assert!(
                error.iter().all(|e| e.abs() < 1e-3),
                "{name} {}: clip {bbox:?}, expected {:?}",
                want.gradient,
                want.clip
            );
        }
    }
}

#[test]
fn content_left_out_is_named() {
    let scene = read(&FILES[9]);
    let warnings = scene
        .warnings
        .iter()
        .map(|w| w.message.as_str())
        .collect::<Vec<_>>()
        .join("\n");
    assert!(
        warnings.contains(r##"<ellipse id="ellipse5941"> at 254:3: fill "#80ffb3" left out"##),
        "{warnings}"
    );
    assert!(
        warnings.contains(r##"<path id="path5996"> at 268:3: stroke "#000000" left out"##),
        "{warnings}"
    );
}

/// The point of the Coons patch `(r, c)` at parameters `(u, v)`: `u` along the rows, `v` down
/// the columns.
fn coons_point(grid: &svg::MeshGrid, r: usize, c: usize, u: f64, v: f64) -> Point {
    let top = grid.row_side(r, c).eval(u).to_vec2();
    let bottom = grid.row_side(r + 1, c).eval(u).to_vec2();
    let left = grid.column_side(r, c).eval(v).to_vec2();
    let right = grid.column_side(r, c + 1).eval(v).to_vec2();
    let corner = |i: usize, j: usize| grid.corner(r + i, c + j).position.to_vec2();
    let bilinear = corner(0, 0) * ((1.0 - u) * (1.0 - v))
        + corner(0, 1) * (u * (1.0 - v))
        + corner(1, 0) * ((1.0 - u) * v)
        + corner(1, 1) * (u * v);
    (top * (1.0 - v) + bottom * v + left * (1.0 - u) + right * u - bilinear).to_point()
}

/// The pixel of a point a little inside the mesh from its outer corner `(i, j)`: at
/// parameters 0.03 from the corner in the patch that has it (a folded mesh may lie on any side
/// of its corners).
fn pixel_inside(opts: &RenderOptions, grid: &svg::MeshGrid, i: usize, j: usize) -> (u32, u32) {
    let (r, c) = (i.min(grid.rows - 1), j.min(grid.columns - 1));
    let u = if j == c { 0.03 } else { 0.97 };
    let v = if i == r { 0.03 } else { 0.97 };
    let q = coons_point(grid, r, c, u, v);
    let view = &opts.view;
    let x = (q.x - view.x0) / view.width() * f64::from(opts.width);
    let y = (q.y - view.y0) / view.height() * f64::from(opts.height);
    (x as u32, y as u32)
}

#[test]
fn converted_files_show_their_stop_colours_at_the_mesh_corners() {
    for expected in FILES {
        let name = expected.file;
        let path = realdata::meshgradient(name);
        let doc = formats::read_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let scene = read(expected);
        assert_eq!(doc.layers.len(), scene.fills.len(), "{name}");
        for (mesh, fill) in doc.layers.iter().zip(&scene.fills) {
            gradmesh::validate(mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
            Limits::DEFAULT.check_mesh(mesh).unwrap();
            assert_eq!(
                mesh.faces.len(),
                fill.mesh.rows * fill.mesh.columns,
                "{name}"
            );
        }
        let [x0, y0, x1, y1] = expected.view;
        let scale = 1.0;
        let (w, h) = (((x1 - x0) * scale) as u32, ((y1 - y0) * scale) as u32);
        let opts = RenderOptions::new(w, h, View::new(x0, y0, x1, y1));
        // Each layer alone: a later mesh, unclipped, may cover an earlier one's corner.
        for (mesh, fill) in doc.layers.iter().zip(&scene.fills) {
            let alone = Document::new(vec![mesh.clone()]);
            let image = render_document(&alone, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
            let grid = &fill.mesh;
            let (r, c) = (grid.rows, grid.columns);
            for (i, j) in [(0, 0), (0, c), (r, c), (r, 0)] {
                let corner = grid.corner(i, j);
                let (x, y) = pixel_inside(&opts, grid, i, j);
                let px = image.pixel(x, y);
                let worst = (0..3)
                    .map(|k| (f64::from(px[k]) - corner.colour[k]).abs())
                    .fold(0.0, f64::max);
                // A little inside, the colour has moved on from the corner's; a thin patch
                // covers its pixel partly (the colour is straight, not premultiplied).
                assert!(
                    worst < 0.1 && px[3] > 0.1,
                    "{name} {}: corner ({i}, {j}) at pixel ({x}, {y}) is {px:?}, its stop {:?}",
                    fill.gradient_id,
                    corner.colour
                );
            }
        }
    }
}
