//! Unit tests of the SVG reader against small hand-written files with closed-form answers.

use kurbo::{CubicBez, Point, Rect, Shape};

use super::*;
use crate::error::ErrorKind;

/// A document around `body`, with a 100 x 100 view box.
fn svg(body: &str) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="200" height="200" viewBox="0 0 100 100">{body}</svg>"#
    )
}

/// One patch of `size` x `size` at (`x`, `y`) in user space, red, green, blue and yellow
/// clockwise from the top left, with straight sides.
fn square_gradient(id: &str, x: f64, y: f64, size: f64, extra: &str) -> String {
    format!(
        r##"<meshgradient id="{id}" x="{x}" y="{y}" gradientUnits="userSpaceOnUse" {extra}><meshrow><meshpatch>
        <stop path="l {size},0" stop-color="#f00"/><stop path="l 0,{size}" stop-color="#0f0"/>
        <stop path="l -{size},0" stop-color="#00f"/><stop path="l 0,-{size}" stop-color="#ff0"/>
        </meshpatch></meshrow></meshgradient>"##
    )
}

fn read(body: &str) -> SvgScene {
    read_svg(&svg(body)).unwrap_or_else(|e| panic!("{e}"))
}

fn error(body: &str) -> String {
    read_svg(&svg(body)).unwrap_err().to_string()
}

/// The warnings of a document whose only shape's mesh-gradient fill is left out.
fn left_out(body: &str) -> String {
    let scene = read(body);
    assert!(scene.fills.is_empty(), "{body}");
    warning_text(&scene.warnings)
}

fn close(a: Point, b: Point) -> bool {
    a.distance(b) < 1e-9
}

fn positions(grid: &MeshGrid) -> Vec<Point> {
    grid.corners.iter().map(|c| c.position).collect()
}

#[test]
fn one_patch_in_user_space() {
    let scene = read(&format!(
        r#"{}<rect x="10" y="20" width="30" height="30" fill="url(#m)"/>"#,
        square_gradient("m", 10.0, 20.0, 30.0, "")
    ));
    assert_eq!(scene.view_box, Some(Rect::new(0.0, 0.0, 100.0, 100.0)));
    assert_eq!((scene.width, scene.height), (Some(200.0), Some(200.0)));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let fill = &scene.fills[0];
    assert_eq!(
        (fill.gradient_id.as_str(), fill.shape_tag.as_str()),
        ("m", "rect")
    );
    let grid = &fill.mesh;
    assert_eq!(
        (grid.rows, grid.columns, grid.kind),
        (1, 1, MeshType::Bilinear)
    );
    let expected = [(10.0, 20.0), (40.0, 20.0), (10.0, 50.0), (40.0, 50.0)];
    for (p, e) in positions(grid).iter().zip(expected) {
        assert!(close(*p, e.into()), "{p:?} != {e:?}");
    }
    // Corner (i, j): red top left, green top right, blue bottom right, yellow bottom left.
    assert_eq!(grid.corner(0, 0).colour, [1.0, 0.0, 0.0]);
    assert_eq!(grid.corner(0, 1).colour, [0.0, 1.0, 0.0]);
    assert_eq!(grid.corner(1, 1).colour, [0.0, 0.0, 1.0]);
    assert_eq!(grid.corner(1, 0).colour, [1.0, 1.0, 0.0]);
    // Straight sides are cubics with handles at thirds.
    let top = grid.row_side(0, 0);
    assert!(close(top.p1, Point::new(20.0, 20.0)) && close(top.p2, Point::new(30.0, 20.0)));
    assert_eq!(fill.clip.bounding_box(), Rect::new(10.0, 20.0, 40.0, 50.0));
}

#[test]
fn transforms_of_gradient_shape_and_ancestors_compose() {
    // Gradient space -> gradientTransform (scale 2) -> rect's translate(5,0) -> group's
    // translate(0,10) -> root.
    let scene = read(&format!(
        r#"{}<g transform="translate(0,10)"><rect transform="translate(5)" width="20" height="20" fill="url(#m)"/></g>"#,
        square_gradient("m", 1.0, 2.0, 10.0, r#"gradientTransform="scale(2)""#)
    ));
    let grid = &scene.fills[0].mesh;
    // (1, 2) -> (2, 4) -> (7, 4) -> (7, 14); the far corner (11, 12) -> (27, 34).
    assert!(close(grid.corner(0, 0).position, Point::new(7.0, 14.0)));
    assert!(close(grid.corner(1, 1).position, Point::new(27.0, 34.0)));
    assert_eq!(
        scene.fills[0].clip.bounding_box(),
        Rect::new(5.0, 10.0, 25.0, 30.0)
    );
}

#[test]
fn relative_and_absolute_paths_give_the_same_patch() {
    let relative = r##"<meshgradient id="m" x="10" y="10" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
        <stop path="c 10,-5 20,5 30,0"/><stop path="l 0,30"/><stop path="c -10,5 -20,-5 -30,0"/><stop path="L 10,10"/>
        </meshpatch></meshrow></meshgradient><rect width="50" height="50" fill="url(#m)"/>"##;
    let absolute = r##"<meshgradient id="m" x="10" y="10" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
        <stop path="C 20,5 30,15 40,10"/><stop path="L 40,40"/><stop path="C 30,45 20,35 10,40"/><stop path="l 0,-30"/>
        </meshpatch></meshrow></meshgradient><rect width="50" height="50" fill="url(#m)"/>"##;
    let (a, b) = (read(relative), read(absolute));
    assert_eq!(a.fills[0].mesh, b.fills[0].mesh);
    let top = a.fills[0].mesh.row_side(0, 0);
    let expected = CubicBez::new((10.0, 10.0), (20.0, 5.0), (30.0, 15.0), (40.0, 10.0));
    assert_eq!(top, expected);
    // The bottom side is stored left to right: its handles are those of the stop, reversed.
    let bottom = a.fills[0].mesh.row_side(1, 0);
    assert_eq!(
        bottom,
        CubicBez::new((10.0, 40.0), (20.0, 35.0), (30.0, 45.0), (40.0, 40.0))
    );
    // Default stop colour: black.
    assert_eq!(a.fills[0].mesh.corner(1, 0).colour, [0.0; 3]);
}

#[test]
fn closing_sides_may_leave_out_their_end_point() {
    let with_end = read(&format!(
        r#"{}<rect width="50" height="50" fill="url(#m)"/>"#,
        square_gradient("m", 0.0, 0.0, 10.0, "")
    ));
    let without = read(
        r##"<meshgradient id="m" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
        <stop path="l 10,0" stop-color="#f00"/><stop path="l 0,10" stop-color="#0f0"/>
        <stop path="l -10,0" stop-color="#00f"/><stop path="l" stop-color="#ff0"/>
        </meshpatch></meshrow></meshgradient><rect width="50" height="50" fill="url(#m)"/>"##,
    );
    assert_eq!(with_end.fills[0].mesh, without.fills[0].mesh);
    // A closing `c` with only its handles.
    let short_c = read(
        r##"<meshgradient id="m" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
        <stop path="l 10,0"/><stop path="l 0,10"/><stop path="l -10,0"/><stop path="c 1,-3 1,-6"/>
        </meshpatch></meshrow></meshgradient><rect width="50" height="50" fill="url(#m)"/>"##,
    );
    let left = short_c.fills[0].mesh.column_side(0, 0);
    assert_eq!(
        left,
        CubicBez::new((0.0, 0.0), (1.0, 4.0), (1.0, 7.0), (0.0, 10.0))
    );
}

/// A 2 x 2 mesh of 10-unit squares whose shared stops carry colours that must be ignored.
const TWO_BY_TWO: &str = r##"<meshgradient id="m" gradientUnits="userSpaceOnUse"><meshrow>
    <meshpatch><stop path="l 10,0" stop-color="#000"/><stop path="l 0,10" stop-color="#100"/><stop path="l -10,0" stop-color="#200"/><stop path="l 0,-10" stop-color="#300"/></meshpatch>
    <meshpatch><stop path="l 10,0" stop-color="#fff"/><stop path="l 0,10" stop-color="#400"/><stop path="l -10,0" stop-color="#500"/></meshpatch>
    </meshrow><meshrow>
    <meshpatch><stop path="l 0,10" stop-color="#fff"/><stop path="l -10,0" stop-color="#600"/><stop path="l 0,-10" stop-color="#700"/></meshpatch>
    <meshpatch><stop path="l 0,10" stop-color="#fff"/><stop path="l -10,0" stop-color="#800"/></meshpatch>
    </meshrow></meshgradient><rect width="20" height="20" fill="url(#m)"/>"##;

#[test]
fn shared_sides_and_corner_colours_come_from_the_first_stop() {
    let scene = read(TWO_BY_TWO);
    let grid = &scene.fills[0].mesh;
    assert_eq!((grid.rows, grid.columns), (2, 2));
    let red = |i: usize, j: usize| (grid.corner(i, j).colour[0] * 15.0).round() as u32;
    // #k00 is k/15 red: corner (i, j) -> k.
    let expected = [[0, 1, 4], [3, 2, 5], [7, 6, 8]];
    for i in 0..3 {
        for j in 0..3 {
            assert_eq!(red(i, j), expected[i][j], "corner ({i}, {j})");
            let p = grid.corner(i, j).position;
            assert!(
                close(p, Point::new(10.0 * j as f64, 10.0 * i as f64)),
                "{p:?}"
            );
        }
    }
    // Patch (1, 1): its top is the bottom of (0, 1), its left the right of (1, 0).
    let [top, right, bottom, left] = grid.patch_sides(1, 1);
    assert_eq!(
        (top.p0, top.p3),
        (Point::new(10.0, 10.0), Point::new(20.0, 10.0))
    );
    assert_eq!(
        (right.p0, right.p3),
        (Point::new(20.0, 10.0), Point::new(20.0, 20.0))
    );
    assert_eq!(
        (bottom.p0, bottom.p3),
        (Point::new(20.0, 20.0), Point::new(10.0, 20.0))
    );
    assert_eq!(
        (left.p0, left.p3),
        (Point::new(10.0, 20.0), Point::new(10.0, 10.0))
    );
}

#[test]
fn object_bounding_box_units() {
    // The initial units are objectBoundingBox: x, y and paths are fractions of the box.
    let scene = read(
        r##"<meshgradient id="m" x="0.5" y="0"><meshrow><meshpatch>
        <stop path="l 0.5,0" stop-color="#f00"/><stop path="l 0,1"/><stop path="l -0.5,0"/><stop path="l 0,-1"/>
        </meshpatch></meshrow></meshgradient>
        <circle cx="50" cy="50" r="20" fill="url(#m)"/>"##,
    );
    let grid = &scene.fills[0].mesh;
    assert!(close(grid.corner(0, 0).position, Point::new(50.0, 30.0)));
    assert!(close(grid.corner(1, 1).position, Point::new(70.0, 70.0)));
    let bbox = scene.fills[0].clip.bounding_box();
    assert!(
        (bbox.x0 - 30.0).abs() < 1e-3 && (bbox.y1 - 70.0).abs() < 1e-3,
        "{bbox:?}"
    );
}

#[test]
fn href_inherits_rows_and_attributes() {
    // `b` takes its rows, units and type from `a`, keeps its own x; `c` (xlink) takes all of
    // `b`'s.
    let scene = read(&format!(
        r##"{}<meshgradient id="b" href="#a" x="50"/><meshgradient id="c" xlink:href="#b"/>
        <rect width="10" height="10" fill="url(#b)"/><rect width="10" height="10" fill="url(#c)"/>"##,
        square_gradient("a", 10.0, 20.0, 5.0, r#"type="bicubic""#)
    ));
    for fill in &scene.fills {
        assert_eq!(fill.mesh.kind, MeshType::Bicubic);
        assert!(close(
            fill.mesh.corner(0, 0).position,
            Point::new(50.0, 20.0)
        ));
        assert!(close(
            fill.mesh.corner(1, 1).position,
            Point::new(55.0, 25.0)
        ));
    }
    // Inkscape 0.91 points a mesh at a linear gradient: the chain ends there.
    let scene = read(&format!(
        r##"<linearGradient id="l"><stop offset="0"/></linearGradient>{}<rect width="10" height="10" fill="url(#m)"/>"##,
        square_gradient("m", 0.0, 0.0, 5.0, r##"xlink:href="#l""##)
    ));
    assert_eq!(scene.fills[0].mesh.rows, 1);
}

#[test]
fn inkscape_091_camel_case_and_style_colours() {
    let scene = read(
        r##"<defs><meshGradient id="m" gradientUnits="userSpaceOnUse" type="coons"><meshRow><meshPatch>
        <stop path="l 10,0" style="stop-color:#ff0000;stop-opacity:0.5"/>
        <stop path="l 0,10" stop-color="#00f" style="stop-color: rgb(0, 255, 0) ; stop-opacity:25%"/>
        <stop path="l -10,0" stop-color="currentColor" stop-opacity="2" color="#0000ff"/>
        <stop path="l 0,-10" stop-color="rgba(255, 255, 0, 0.5)" stop-opacity="0.5"/>
        </meshPatch></meshRow></meshGradient></defs>
        <rect width="10" height="10" style="fill:url(#m);fill-opacity:0.5" opacity="0.5"/>"##,
    );
    let fill = &scene.fills[0];
    let grid = &fill.mesh;
    assert_eq!(grid.kind, MeshType::Coons);
    let corner = |i, j| (grid.corner(i, j).colour, grid.corner(i, j).opacity);
    assert_eq!(corner(0, 0), ([1.0, 0.0, 0.0], 0.5));
    // The style wins over the attribute.
    assert_eq!(corner(0, 1), ([0.0, 1.0, 0.0], 0.25));
    // currentColor; opacities are clamped to 1.
    assert_eq!(corner(1, 1), ([0.0, 0.0, 1.0], 1.0));
    // The colour's alpha (128/255) times stop-opacity.
    assert_eq!(corner(1, 0).0, [1.0, 1.0, 0.0]);
    assert!((corner(1, 0).1 - 0.5 * 128.0 / 255.0).abs() < 1e-12);
    assert_eq!((fill.fill_opacity, fill.group_opacity), (0.5, 0.5));
}

#[test]
fn other_content_is_named_in_warnings() {
    let scene = read(&format!(
        r##"{}<rect id="flat" width="5" height="5" fill="#f00"/><text id="t">hi</text>
        <path id="p" d="M0 0 L 10 0 L 10 10 z" fill="url(#m)" stroke="#000"/><rect id="none" width="5" height="5" fill="none"/>"##,
        square_gradient("m", 0.0, 0.0, 10.0, "")
    ));
    assert_eq!(scene.fills.len(), 1);
    let all = warning_text(&scene.warnings);
    assert!(
        all.contains(r#"<rect id="flat"> at 4:46"#) && all.contains("fill \"#f00\" left out"),
        "{all}"
    );
    assert!(all.contains(r#"<text id="t">"#), "{all}");
    assert!(
        all.contains(r#"<path id="p">"#) && all.contains("stroke \"#000\" left out"),
        "{all}"
    );
    assert!(!all.contains("none"), "{all}");
}

#[test]
fn mesh_errors_leave_the_fill_out_naming_the_element_and_its_place() {
    let gradient = |stops: &str| {
        format!(
            r##"<meshgradient id="m" gradientUnits="userSpaceOnUse"><meshrow><meshpatch id="p">{stops}</meshpatch></meshrow></meshgradient>
<rect width="5" height="5" fill="url(#m)"/>"##
        )
    };
    let e = left_out(&gradient(r#"<stop path="l 1,0"/><stop path="l 0,1"/>"#));
    assert!(
        e.starts_with(r#"<rect> at 2:1: its mesh-gradient fill is left out: line 1: <meshpatch id="p"> at column "#),
        "{e}"
    );
    assert!(
        e.ends_with("has 2 stops; it needs 4 (one per side not shared with an earlier patch)"),
        "{e}"
    );
    let e = left_out(&gradient(r#"<stop id="s" path="l 1,0 l 0,1"/>"#));
    assert!(
        e.contains(r#"<stop id="s"> at column"#) && e.contains("is not one l, L, c or C command"),
        "{e}"
    );
    let e = left_out(&gradient(r#"<stop id="s" path="z"/>"#));
    assert!(e.contains("\"z\" is not one l, L, c or C command"), "{e}");
    let e = left_out(&gradient(r#"<stop path="c 1,2"/>"#));
    assert!(
        e.ends_with("path \"c 1,2\": c takes 6 numbers, found 2"),
        "{e}"
    );
    let e = left_out(&gradient(r#"<stop path="l 1e999,0"/>"#));
    assert!(
        e.ends_with("path \"l 1e999,0\" is not one l, L, c or C command"),
        "{e}"
    );
    let e = error(&format!(
        "<g transform=\"scale(1e300)\">{}</g>",
        gradient(
            r#"<stop path="l 1e300,0"/><stop path="l 0,1"/><stop path="l -1,0"/><stop path="l 0,-1"/>"#
        )
    ));
    assert!(
        e.ends_with("its mesh or outline has coordinates too large to represent"),
        "{e}"
    );
    let e = left_out(&gradient(r#"<stop path="l 1,0" stop-color="nocolour"/>"#));
    assert!(e.contains("stop-color \"nocolour\" is not a colour"), "{e}");
    // A second line: the line is counted.
    let e = left_out(&gradient(
        r#"<stop path="l 1,0"/>
<stop path="l 0,1" stop-opacity="NaN"/>"#,
    ));
    assert!(
        e.contains("fill is left out: line 2: <stop> at column 1: stop-opacity"),
        "{e}"
    );
}

#[test]
fn reference_loops_leave_the_fill_out_and_entities_are_refused() {
    let e = left_out(
        r##"<meshgradient id="a" href="#b"/><meshgradient id="b" href="#a"/><rect width="1" height="1" fill="url(#a)"/>"##,
    );
    assert!(
        e.contains(r#"<meshgradient id="a">"#) && e.ends_with("its href chain loops back to #a"),
        "{e}"
    );
    let e = left_out(
        r##"<meshgradient id="a" href="other.svg#b"/><rect width="1" height="1" fill="url(#a)"/>"##,
    );
    assert!(e.ends_with("href \"other.svg#b\" is not a reference into this file (#id); other files are never read"), "{e}");
    let e = left_out(
        r##"<meshgradient id="a" href="#nothing"/><rect width="1" height="1" fill="url(#a)"/>"##,
    );
    assert!(
        e.ends_with("href names #nothing, which no element has"),
        "{e}"
    );
    let laughs = "<?xml version=\"1.0\"?>\n<!DOCTYPE svg [\n<!ENTITY a \"aaaaaaaaaa\">\n<!ENTITY b \"&a;&a;&a;&a;\">\n]>\n<svg xmlns=\"http://www.w3.org/2000/svg\">&b;</svg>";
    let e = read_svg(laughs).unwrap_err();
    assert_eq!(
        e.to_string(),
        "3: the file declares an XML entity; entities are not read, for safety"
    );
    // A DOCTYPE without entities is read.
    let doctype = format!("<!DOCTYPE svg PUBLIC \"-//W3C//DTD SVG 1.1//EN\" \"http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd\">\n{}", svg(""));
    assert!(read_svg(&doctype).is_ok());
    let e = read_svg("<svg xmlns=\"http://www.w3.org/2000/svg\">\n<rect></svg>").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("2: the file is not well-formed XML"),
        "{e}"
    );
    let e = read_svg("<html/>").unwrap_err();
    assert!(
        e.to_string().ends_with("the root element is not <svg>"),
        "{e}"
    );
}

#[test]
fn limits_are_checked_before_the_mesh_is_built() {
    let patch =
        r#"<meshpatch><stop path="l 1,0"/><stop path="l 0,1"/><stop path="l -1,0"/></meshpatch>"#;
    let body = format!(
        r##"<meshgradient id="m" gradientUnits="userSpaceOnUse"><meshrow>{}</meshrow></meshgradient><rect width="1" height="1" fill="url(#m)"/>"##,
        patch.repeat(10)
    );
    let limits = Limits {
        faces: 5,
        ..Limits::DEFAULT
    };
    let e = read_svg_with_limits(&svg(&body), &limits).unwrap_err();
    assert!(
        matches!(
            e.kind,
            ErrorKind::LimitExceeded {
                found: 10,
                limit: 5,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.kind.to_string(),
        "the number of mesh patches is 10, above the limit of 5"
    );
    // Two fills of 4 patches against a limit of 5: counted over all fills.
    let four = body.replacen(
        &patch.repeat(10),
        &format!(
            "<meshpatch><stop path=\"l 1,0\"/>{}",
            &patch.repeat(4)[10..]
        ),
        1,
    );
    let twice = format!("{four}<rect width=\"1\" height=\"1\" fill=\"url(#m)\"/>");
    let e = read_svg_with_limits(&svg(&twice), &limits).unwrap_err();
    assert_eq!(
        e.kind.to_string(),
        "the number of mesh patches over all fills is 8, above the limit of 5"
    );
    let limits = Limits {
        input_bytes: 10,
        ..Limits::DEFAULT
    };
    assert!(matches!(
        read_svg_with_limits(&svg(""), &limits).unwrap_err().kind,
        ErrorKind::LimitExceeded { .. }
    ));
    let deep = format!(
        "{}{}",
        "<g>".repeat(MAX_DEPTH + 1),
        "</g>".repeat(MAX_DEPTH + 1)
    );
    let e = read_svg(&svg(&deep)).unwrap_err();
    assert!(
        e.to_string()
            .contains("the nesting depth of elements is 1,025, above the limit of 1,024"),
        "{e}"
    );
}

#[test]
fn rows_must_have_the_same_length() {
    let e = left_out(
        r##"<meshgradient id="m"><meshrow><meshpatch/><meshpatch/></meshrow><meshrow id="r"><meshpatch/></meshrow></meshgradient><rect width="1" height="1" fill="url(#m)"/>"##,
    );
    assert!(e.contains(r#"<meshrow id="r">"#) && e.ends_with("the row has 1 patches, but the first row has 2; every row must have the same number"), "{e}");
}

#[test]
fn shapes_give_their_outlines() {
    let gradient = square_gradient("m", 0.0, 0.0, 1.0, "");
    let bbox = |shape: &str| {
        let scene = read(&format!("{gradient}{shape}"));
        scene.fills[0].clip.bounding_box()
    };
    let near = |a: Rect, b: Rect| {
        [a.x0 - b.x0, a.y0 - b.y0, a.x1 - b.x1, a.y1 - b.y1]
            .iter()
            .all(|d| d.abs() < 1e-3)
    };
    let cases = [
        (
            r#"<rect x="1" y="2" width="3" height="4" rx="1" ry="2" fill="url(#m)"/>"#,
            Rect::new(1.0, 2.0, 4.0, 6.0),
        ),
        (
            r#"<circle cx="10" cy="10" r="5" fill="url(#m)"/>"#,
            Rect::new(5.0, 5.0, 15.0, 15.0),
        ),
        (
            r#"<ellipse cx="10" cy="10" rx="5" ry="2" transform="rotate(90 10 10)" fill="url(#m)"/>"#,
            Rect::new(8.0, 5.0, 12.0, 15.0),
        ),
        (
            r#"<polygon points="0,0 10,0 5,8" fill="url(#m)"/>"#,
            Rect::new(0.0, 0.0, 10.0, 8.0),
        ),
        (
            r#"<path d="M 0 0 h 10 v 10 z" fill="url(#m)"/>"#,
            Rect::new(0.0, 0.0, 10.0, 10.0),
        ),
        (
            r#"<rect width="50%" height="10mm" fill="url(#m)"/>"#,
            Rect::new(0.0, 0.0, 50.0, 96.0 / 2.54),
        ),
    ];
    for (shape, expected) in cases {
        let found = bbox(shape);
        assert!(near(found, expected), "{shape}: {found:?} != {expected:?}");
    }
    // Rounded corners: the outline stays inside the rectangle and misses its corner.
    let scene = read(&format!(
        r#"{gradient}<rect width="10" height="10" rx="3" fill="url(#m)"/>"#
    ));
    assert!(!scene.fills[0].clip.contains(Point::new(0.5, 0.5)));
    assert!(scene.fills[0].clip.contains(Point::new(5.0, 0.5)));
}

#[test]
fn conversion_makes_one_point_per_corner_and_one_quad_per_patch() {
    let scene = read(TWO_BY_TWO);
    let (doc, warnings) = scene_to_document(&scene, ColourSpace::Lab);
    assert!(warnings.is_empty(), "{warnings:?}");
    let mesh = &doc.layers[0];
    assert_eq!((mesh.points.len(), mesh.faces.len()), (9, 4));
    assert_eq!(mesh.faces[3], vec![4, 5, 8, 7]);
    assert_eq!(mesh.name.as_deref(), Some("m"));
    // Straight sides: every handle is the default third, so none is stored.
    assert!(mesh.handles.is_empty());
    for (point, corner) in mesh.points.iter().zip(&scene.fills[0].mesh.corners) {
        let back = ColourSpace::Lab.convert(ColourSpace::Srgb, point.colour);
        for k in 0..3 {
            assert!(
                (back[k] - corner.colour[k]).abs() < 1e-6,
                "{back:?} vs {:?}",
                corner.colour
            );
        }
    }
    assert_eq!(mesh.points[0].colour_text.as_deref(), Some("#000000"));
    assert!(crate::validate(mesh).is_ok());
}

#[test]
fn conversion_takes_handles_and_opacity() {
    let scene = read(
        r##"<meshgradient id="m" x="0" y="0" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
        <stop path="c 10,-5 20,5 30,0" stop-opacity="0.5"/><stop path="l 0,30"/><stop path="l -30,0"/><stop path="l 0,-30"/>
        </meshpatch></meshrow></meshgradient><rect width="30" height="30" fill="url(#m)" fill-opacity="0.5"/>"##,
    );
    let (doc, _) = scene_to_document(&scene, ColourSpace::Oklab);
    let mesh = &doc.layers[0];
    assert_eq!(mesh.colour_space, ColourSpace::Oklab);
    assert_eq!(mesh.points[0].opacity, 0.25);
    assert_eq!(mesh.points[1].opacity, 0.5);
    assert_eq!(mesh.handles.len(), 2);
    assert_eq!(mesh.handle(0, 1), kurbo::Vec2::new(10.0, -5.0));
    assert_eq!(mesh.handle(1, 0), kurbo::Vec2::new(-10.0, 5.0));
}

#[test]
fn sides_of_zero_length_merge_their_corners() {
    // Two rows; the second row's bottom side has zero length (a fan meeting at (10, 20)), as
    // in the WPT star.
    let scene = read(
        r##"<meshgradient id="m" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
        <stop path="l 20,0" stop-color="#f00"/><stop path="l 0,10"/><stop path="l -20,0"/><stop path="l 0,-10"/>
        </meshpatch></meshrow><meshrow><meshpatch>
        <stop path="l -10,10"/><stop path="l 0,0" stop-color="#00f"/><stop path="l 0,-10" stop-color="#0f0"/>
        </meshpatch></meshrow></meshgradient><rect width="20" height="20" fill="url(#m)"/>"##,
    );
    let (doc, warnings) = scene_to_document(&scene, ColourSpace::Lab);
    let mesh = &doc.layers[0];
    assert_eq!(mesh.points.len(), 5);
    assert_eq!(mesh.faces, vec![vec![0, 1, 3, 2], vec![2, 3, 4]]);
    // The two bottom corners had different colours: the first (bottom left) is kept.
    assert_eq!(mesh.points[4].colour_text.as_deref(), Some("#00ff00"));
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0]
            .message
            .contains("corner (2, 1) meets corner (2, 0)"),
        "{}",
        warnings[0]
    );
    assert!(crate::validate(mesh).is_ok());
}

#[test]
fn a_file_without_mesh_fills_is_an_error() {
    let e = read_document_with_limits(
        &svg("<rect width=\"1\" height=\"1\"/>"),
        ColourSpace::Lab,
        &Limits::DEFAULT,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "the SVG document: no shape is filled with a mesh gradient"
    );
}

#[test]
fn invalid_attributes_are_ignored_with_a_warning() {
    let scene = read(&format!(
        r##"{}
<rect x="110" y="10" width="80" height="80" opacity="1x"/>
<rect width="5" height="5" fill="url(#m)" transform="qwe" fill-opacity="half"/>"##,
        square_gradient("m", 0.0, 0.0, 10.0, "")
    ));
    assert_eq!(scene.fills.len(), 1);
    assert_eq!(scene.fills[0].fill_opacity, 1.0);
    assert_eq!(
        scene.fills[0].clip.bounding_box(),
        Rect::new(0.0, 0.0, 5.0, 5.0)
    );
    let all = warning_text(&scene.warnings);
    for expected in [
        r#"<rect> at 5:1: opacity "1x" is not a number"#,
        r#"<rect> at 6:1: transform "qwe" is not a transform list"#,
        r#"<rect> at 6:1: fill-opacity "half" is not a number"#,
    ] {
        assert!(all.contains(expected), "{expected} in {all}");
    }
    assert_eq!(all.matches(": ignored").count(), 3, "{all}");
    // The root's invalid width is ignored too: the view box gives the size.
    let text = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="wide" viewBox="0 0 40 20">{}<rect width="5" height="5" fill="url(#m)"/></svg>"#,
        square_gradient("m", 0.0, 0.0, 10.0, "")
    );
    let scene = read_svg(&text).unwrap();
    assert_eq!(scene.pixel_size(), (40.0, 20.0));
    assert!(
        scene.warnings[0]
            .message
            .contains(r#"width "wide" is not a length"#),
        "{:?}",
        scene.warnings
    );
}

/// The root's `preserveAspectRatio` fits the view box into the picture: `meet` grows the view
/// to fill it, `slice` cuts the view box, `none` stretches it.
#[test]
fn preserve_aspect_ratio_fits_the_view_box() {
    let view = |aspect: &str| {
        let text = format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100" viewBox="0 0 200 200" {aspect}>{}<rect width="5" height="5" fill="url(#m)"/></svg>"#,
            square_gradient("m", 0.0, 0.0, 10.0, "")
        );
        read_svg(&text).unwrap().view_rect()
    };
    let r = |x0, y0, x1, y1| Rect::new(x0, y0, x1, y1);
    assert_eq!(view(""), r(-100.0, 0.0, 300.0, 200.0));
    assert_eq!(
        view(r#"preserveAspectRatio="xMidYMid meet""#),
        r(-100.0, 0.0, 300.0, 200.0)
    );
    assert_eq!(
        view(r#"preserveAspectRatio="xMinYMin""#),
        r(0.0, 0.0, 400.0, 200.0)
    );
    assert_eq!(
        view(r#"preserveAspectRatio="xMaxYMax meet""#),
        r(-200.0, 0.0, 200.0, 200.0)
    );
    assert_eq!(
        view(r#"preserveAspectRatio="xMidYMid slice""#),
        r(0.0, 50.0, 200.0, 150.0)
    );
    assert_eq!(
        view(r#"preserveAspectRatio="xMinYMin slice""#),
        r(0.0, 0.0, 200.0, 100.0)
    );
    assert_eq!(
        view(r#"preserveAspectRatio="xMaxYMax slice""#),
        r(0.0, 100.0, 200.0, 200.0)
    );
    assert_eq!(
        view(r#"preserveAspectRatio="none""#),
        r(0.0, 0.0, 200.0, 200.0)
    );
    // Invalid: the initial value, with a warning.
    assert_eq!(
        view(r#"preserveAspectRatio="sideways""#),
        r(-100.0, 0.0, 300.0, 200.0)
    );
    // Aspect ratios a millionth apart (an editor's rounding) show the view box itself.
    let b = r(0.0, 0.0, 600.00005, 399.99998);
    assert_eq!(AspectRatio::default().fit(b, 600.0, 400.0), b);
}

/// A root without a size (or a zero one) has CSS's default size, 300 x 150, unless its view
/// box gives the size or the ratio.
#[test]
fn a_missing_or_zero_size_is_the_css_default_or_the_view_box() {
    let size = |attributes: &str| {
        let text = format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" {attributes}>{}<rect width="5" height="5" fill="url(#m)"/></svg>"#,
            square_gradient("m", 0.0, 0.0, 10.0, "")
        );
        let scene = read_svg(&text).unwrap();
        (scene.pixel_size(), scene.view_rect())
    };
    let r = |x0, y0, x1, y1| Rect::new(x0, y0, x1, y1);
    assert_eq!(size(""), ((300.0, 150.0), r(0.0, 0.0, 300.0, 150.0)));
    assert_eq!(
        size(r#"width="0" height="0""#),
        ((300.0, 150.0), r(0.0, 0.0, 300.0, 150.0))
    );
    assert_eq!(
        size(r#"width="50""#),
        ((50.0, 150.0), r(0.0, 0.0, 50.0, 150.0))
    );
    assert_eq!(
        size(r#"viewBox="0 0 40 20""#),
        ((40.0, 20.0), r(0.0, 0.0, 40.0, 20.0))
    );
    assert_eq!(
        size(r#"width="80" viewBox="0 0 40 20""#),
        ((80.0, 40.0), r(0.0, 0.0, 40.0, 20.0))
    );
    assert_eq!(
        size(r#"height="0" viewBox="0 0 40 20""#),
        ((40.0, 20.0), r(0.0, 0.0, 40.0, 20.0))
    );
}

/// The messages of `warnings`, a line each.
fn warning_text(warnings: &[crate::Warning]) -> String {
    let lines: Vec<&str> = warnings.iter().map(|w| w.message.as_str()).collect();
    lines.join("\n")
}

/// A 1-patch mesh `id` over (10, 10)-(40, 40) whose four corners are `grey`.
fn grey_gradient(id: &str, grey: &str) -> String {
    format!(
        r##"<meshgradient id="{id}" x="10" y="10" gradientUnits="userSpaceOnUse"><meshrow><meshpatch>
        <stop path="l 30,0" stop-color="{grey}"/><stop path="l 0,30" stop-color="{grey}"/>
        <stop path="l -30,0" stop-color="{grey}"/><stop path="l 0,-30" stop-color="{grey}"/>
        </meshpatch></meshrow></meshgradient>"##
    )
}

#[test]
fn a_mask_of_matching_meshes_is_read_into_the_opacity() {
    let colours = square_gradient("m", 10.0, 10.0, 30.0, "");
    let body = |mask: &str, grey: &str| {
        format!(
            r#"{colours}{}<mask id="a">{mask}</mask><g mask="url(#a)"><rect x="10" y="10" width="30" height="30" fill="url(#m)"/></g>"#,
            grey_gradient("g", grey)
        )
    };
    // The mask's grey (its luminance), times its stop-opacity, multiplies each corner's opacity.
    let scene = read(&body(
        r#"<rect x="9" y="9" width="32" height="32" fill="url(#g) none"/>"#,
        "#808080",
    ));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    for corner in &scene.fills[0].mesh.corners {
        assert!((corner.opacity - 128.0 / 255.0).abs() < 1e-9, "{corner:?}");
    }
    // A mask whose mesh lies elsewhere, or that holds other content, is left out and named.
    for mask in [
        r#"<rect x="9" y="9" width="32" height="32" fill="url(#g)" transform="translate(1 0)"/>"#,
        r##"<rect x="9" y="9" width="32" height="32" fill="#fff"/>"##,
    ] {
        let scene = read(&body(mask, "#808080"));
        assert!(scene.fills[0].mesh.corners.iter().all(|c| c.opacity == 1.0));
        let text = warning_text(&scene.warnings);
        assert!(text.contains("mask \"url(#a)\" left out"), "{text}");
    }
    // A mask over content that is not a mesh fill is not gradmesh's to read: no warning.
    let scene = read(&format!(
        r##"{colours}<rect x="10" y="10" width="30" height="30" fill="url(#m)"/><mask id="b"/><g mask="url(#b)"/>"##
    ));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

/// gradmesh's SVG export writes a translucent layer as opaque meshes with a mask of grey
/// meshes: reading it back gives the layer its opacity again, within the 8 bits of a grey.
#[test]
fn an_exported_translucent_layer_reads_back_translucent() {
    use crate::export::{write_svg, ExportOptions};
    use crate::mesh::{Document, GradientMesh};
    use crate::view::View;
    let mut mesh = GradientMesh::new(crate::colour::ColourSpace::Lab);
    let opacities = [1.0, 0.2, 0.6, 0.4];
    let p = [(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)]
        .map(|(x, y)| mesh.add_point(Point::new(x, y), [60.0, 20.0, 30.0]));
    for (id, opacity) in p.iter().zip(opacities) {
        mesh.points[*id as usize].opacity = opacity;
    }
    mesh.add_face(p.to_vec());
    let doc = Document::new(vec![mesh]);
    let opts = ExportOptions::new(64, 64, View::new(-5.0, -5.0, 105.0, 105.0));
    let (bytes, _) = write_svg(&doc, &opts, true).unwrap();
    let scene = read_svg(std::str::from_utf8(&bytes).unwrap()).unwrap();
    let text = warning_text(&scene.warnings);
    assert!(!text.contains("mask"), "{text}");
    assert!(!scene.fills.is_empty());
    // The corners of the exported quad, in pixels.
    let scale = 64.0 / 110.0;
    let at = |x: f64, y: f64| Point::new((x + 5.0) * scale, (y + 5.0) * scale);
    for ((x, y), opacity) in [(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)]
        .into_iter()
        .zip(opacities)
    {
        let corner = scene
            .fills
            .iter()
            .flat_map(|f| &f.mesh.corners)
            .find(|c| c.position.distance(at(x, y)) < 2e-3)
            .unwrap_or_else(|| panic!("no corner at ({x}, {y})"));
        assert!(
            (corner.opacity - opacity).abs() <= 0.5 / 255.0 + 1e-9,
            "{corner:?}"
        );
    }
}
