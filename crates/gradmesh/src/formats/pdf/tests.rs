//! PDF files written by hand: what is read from them, and clear errors on hostile ones.

use kurbo::{Point, Rect};

use super::*;
use crate::colour::ColourSpace;
use crate::size_limits::Limits;

/// A PDF file of the given objects (numbered from 1; object 1 is the catalog), with a correct
/// cross-reference table, and `trailer_extra` added to the trailer.
fn pdf_file(objects: &[Vec<u8>], trailer_extra: &str) -> Vec<u8> {
    let mut out = b"%PDF-1.7\n".to_vec();
    let mut offsets = Vec::new();
    for (k, body) in objects.iter().enumerate() {
        offsets.push(out.len());
        out.extend(format!("{} 0 obj\n", k + 1).as_bytes());
        out.extend(body);
        out.extend(b"\nendobj\n");
    }
    let xref = out.len();
    out.extend(format!("xref\n0 {}\n0000000000 65535 f \n", objects.len() + 1).as_bytes());
    for o in offsets {
        out.extend(format!("{o:010} 00000 n \n").as_bytes());
    }
    out.extend(
        format!(
            "trailer\n<< /Size {} /Root 1 0 R {trailer_extra} >>\nstartxref\n{xref}\n%%EOF\n",
            objects.len() + 1
        )
        .as_bytes(),
    );
    out
}

fn stream(dict: &str, data: &[u8]) -> Vec<u8> {
    let mut s = format!("<< {dict} /Length {} >>\nstream\n", data.len()).into_bytes();
    s.extend(data);
    s.extend(b"\nendstream");
    s
}

/// One type 6 patch over (0, 0)-(255, 255), 8-bit everything, flag 0, corners red, green,
/// blue, white (stream order c00, c03, c33, c30).
fn coons_record() -> Vec<u8> {
    let mut data = vec![0u8];
    let points: [(u8, u8); 12] = [
        (0, 0),
        (0, 85),
        (0, 170),
        (0, 255),
        (85, 255),
        (170, 255),
        (255, 255),
        (255, 170),
        (255, 85),
        (255, 0),
        (170, 0),
        (85, 0),
    ];
    data.extend(points.iter().flat_map(|&(x, y)| [x, y]));
    data.extend([255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]);
    data
}

const SHADING_DICT: &str = "/ShadingType 6 /ColorSpace /DeviceRGB /BitsPerCoordinate 8 /BitsPerComponent 8 /BitsPerFlag 8 /Decode [0 255 0 255 0 1 0 1 0 1]";

/// A page of 300 x 200 points painting object 5 (a shading) with `content`.
fn page_with(content: &str, shading: Vec<u8>, more: Vec<Vec<u8>>) -> Vec<u8> {
    let mut objects = vec![
        b"<< /Type /Catalog /Pages 2 0 R >>".to_vec(),
        b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_vec(),
        b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 300 200] /Contents 4 0 R /Resources << /Shading << /S0 5 0 R >> /Pattern << /P0 6 0 R >> >> >>".to_vec(),
        stream("", content.as_bytes()),
        shading,
        b"<< /PatternType 2 /Shading 5 0 R /Matrix [1 0 0 1 10 20] >>".to_vec(),
    ];
    objects.extend(more);
    pdf_file(&objects, "")
}

#[test]
fn a_coons_patch_painted_by_sh_is_read_in_picture_units() {
    let file = page_with(
        "q 1 0 0 1 5 -10 cm /S0 sh Q",
        stream(SHADING_DICT, &coons_record()),
        vec![],
    );
    let picture = read_pdf(&file, 1, &Limits::DEFAULT).unwrap();
    assert_eq!((picture.page, picture.pages), (1, 1));
    assert_eq!(picture.view_rect(), Rect::new(0.0, 0.0, 300.0, 200.0));
    let fill = &picture.fills[0];
    assert_eq!((fill.object.as_str(), fill.shading_type), ("object 5", 6));
    assert!(fill.clip.is_none(), "{:?}", fill.clip);
    let p = &fill.patches[0];
    // (0, 0) in shading space, moved by (5, -10), then y flipped in the 200 pt page.
    assert_eq!(p.points[0][0], Point::new(5.0, 210.0));
    assert_eq!(p.points[3][3], Point::new(260.0, -45.0));
    assert_eq!(fill.srgb_at(p, 0.0, 0.0), [1.0, 0.0, 0.0]);
    assert_eq!(fill.srgb_at(p, 0.0, 1.0), [0.0, 1.0, 0.0]);
    assert_eq!(fill.srgb_at(p, 1.0, 1.0), [0.0, 0.0, 1.0]);
    assert_eq!(fill.srgb_at(p, 1.0, 0.0), [1.0, 1.0, 1.0]);
    // One layer of one face with its four points.
    let (doc, _) = picture_to_document(&picture, ColourSpace::Lab);
    assert_eq!(
        (doc.layers[0].points.len(), doc.layers[0].faces.len()),
        (4, 1)
    );
}

#[test]
fn a_pattern_fill_is_clipped_to_its_path_and_placed_by_the_pattern_matrix() {
    let content = "/Pattern cs /P0 scn 0 0 100 50 re f";
    let file = page_with(content, stream(SHADING_DICT, &coons_record()), vec![]);
    let picture = read_pdf(&file, 1, &Limits::DEFAULT).unwrap();
    let fill = &picture.fills[0];
    assert_eq!(fill.patches[0].points[0][0], Point::new(10.0, 180.0));
    let (clip, _) = fill.clip.as_ref().expect("the filled rectangle clips");
    let b = kurbo::Shape::bounding_box(clip);
    assert_eq!((b.x0, b.y0, b.x1, b.y1), (0.0, 150.0, 100.0, 200.0));
}

#[test]
fn a_function_gives_the_colour_of_the_parametric_value() {
    let mut data = vec![0u8];
    data.extend(coons_record()[1..25].iter());
    data.extend([0, 255, 255, 0]);
    let dict = "/ShadingType 6 /ColorSpace /DeviceRGB /BitsPerCoordinate 8 /BitsPerComponent 8 /BitsPerFlag 8 /Decode [0 255 0 255 0 1] /Function << /FunctionType 2 /Domain [0 1] /C0 [1 0 0] /C1 [0 0 1] /N 1 >>";
    let file = page_with("/S0 sh", stream(dict, &data), vec![]);
    let picture = read_pdf(&file, 1, &Limits::DEFAULT).unwrap();
    let fill = &picture.fills[0];
    let p = &fill.patches[0];
    assert_eq!(fill.srgb_at(p, 0.0, 0.0), [1.0, 0.0, 0.0]);
    // Halfway along v at u = 0: t = 0.5, half red and half blue.
    assert_eq!(fill.srgb_at(p, 0.0, 0.5), [0.5, 0.0, 0.5]);
}

/// The message of reading `file`'s page 1, which must fail.
fn error_of(file: &[u8]) -> String {
    read_pdf(file, 1, &Limits::DEFAULT).unwrap_err().to_string()
}

#[test]
fn hostile_files_are_clear_errors() {
    // Truncated shading stream: the record stops half way.
    let short = &coons_record()[..20];
    let e = error_of(&page_with("/S0 sh", stream(SHADING_DICT, short), vec![]));
    assert!(
        e.contains("object 5") && e.contains("ends inside the patch"),
        "{e}"
    );
    // A Decode array of the wrong length.
    let dict = SHADING_DICT.replace("0 1 0 1 0 1]", "0 1]");
    let e = error_of(&page_with("/S0 sh", stream(&dict, &coons_record()), vec![]));
    assert!(
        e.contains("object 5 /Decode") && e.contains("expected 10 numbers"),
        "{e}"
    );
    // A bit width the format does not have.
    let dict = SHADING_DICT.replace("/BitsPerCoordinate 8", "/BitsPerCoordinate 7");
    let e = error_of(&page_with("/S0 sh", stream(&dict, &coons_record()), vec![]));
    assert!(
        e.contains("BitsPerCoordinate") && e.contains("7 is not one of"),
        "{e}"
    );
    // A reference loop: the shading's colour space refers to itself.
    let dict = SHADING_DICT.replace("/ColorSpace /DeviceRGB", "/ColorSpace 7 0 R");
    let e = error_of(&page_with(
        "/S0 sh",
        stream(&dict, &coons_record()),
        vec![b"8 0 R".to_vec(), b"7 0 R".to_vec()],
    ));
    assert!(e.contains("loop"), "{e}");
    // Absurd patch counts: more than the limit allows, refused before they are read.
    let limits = Limits {
        faces: 3,
        ..Limits::DEFAULT
    };
    let many: Vec<u8> = coons_record().repeat(10);
    let file = page_with("/S0 sh", stream(SHADING_DICT, &many), vec![]);
    let e = read_pdf(&file, 1, &limits).unwrap_err().to_string();
    assert!(e.contains("above the limit of 3"), "{e}");
    // A form that draws itself.
    let form = stream(
        "/Type /XObject /Subtype /Form /BBox [0 0 10 10] /Resources << /XObject << /F 7 0 R >> >>",
        b"/F Do",
    );
    let file = page_with(
        "/F Do",
        stream(SHADING_DICT, &coons_record()),
        vec![form.clone(), form],
    );
    let file = String::from_utf8_lossy(&file).replace(
        "/Pattern << /P0 6 0 R >>",
        "/Pattern << /P0 6 0 R >> /XObject << /F 7 0 R >>",
    );
    let e = error_of(file.as_bytes());
    assert!(
        e.contains("draws itself") || e.contains("deeper than"),
        "{e}"
    );
    // Not a PDF, and a page that is not there.
    assert!(error_of(b"hello").contains("not a PDF file"));
    let file = page_with("/S0 sh", stream(SHADING_DICT, &coons_record()), vec![]);
    let e = read_pdf(&file, 2, &Limits::DEFAULT)
        .unwrap_err()
        .to_string();
    assert!(e.contains("1 page; there is no page 2"), "{e}");
}

#[test]
fn an_encrypted_file_is_refused() {
    let file = pdf_file(
        &[
            b"<< /Type /Catalog /Pages 2 0 R >>".to_vec(),
            b"<< /Type /Pages /Kids [] /Count 0 >>".to_vec(),
            b"<< /Filter /Standard /V 1 /R 2 /O <00> /U <00> /P -4 >>".to_vec(),
        ],
        "/Encrypt 3 0 R /ID [<00112233445566778899aabbccddeeff> <00112233445566778899aabbccddeeff>]",
    );
    let e = error_of(&file);
    assert!(
        e.to_lowercase().contains("encrypt") || e.contains("password"),
        "{e}"
    );
}

#[test]
fn ai_files_are_pdf_inside() {
    assert!(is_pdf(b"%!PS-Adobe\n%PDF-1.5\n"));
    assert!(!is_pdf(b"<svg/>"));
    assert!(crate::formats::is_pdf_path(std::path::Path::new("x.AI")));
}

/// A type 6 record of [`coons_record`]'s patch with one component a corner, `corners` in
/// stream order (c00, c03, c33, c30).
fn one_component_record(corners: [u8; 4]) -> Vec<u8> {
    let mut data = coons_record()[..25].to_vec();
    data.extend(corners);
    data
}

/// A shading dictionary of one 8-bit component a corner in `space`, decoded to `range`.
fn one_component_shading(space: &str, range: &str) -> String {
    format!(
        "/ShadingType 6 /ColorSpace {space} /BitsPerCoordinate 8 /BitsPerComponent 8 \
         /BitsPerFlag 8 /Decode [0 255 0 255 {range}]"
    )
}

/// The fill of page 1 of a page painting a shading of `dict` with `corners`, `more` from
/// object 7.
fn read_one(dict: &str, corners: [u8; 4], more: Vec<Vec<u8>>) -> Result<ShadingFill, String> {
    let file = page_with("/S0 sh", stream(dict, &one_component_record(corners)), more);
    let mut picture = read_pdf(&file, 1, &Limits::DEFAULT).map_err(|e| e.to_string())?;
    Ok(picture.fills.remove(0))
}

fn assert_near(got: [f64; 3], expected: [f64; 3]) {
    let close = got.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-9);
    assert!(close, "{got:?} against {expected:?}");
}

#[test]
fn indexed_corners_round_to_their_entries() {
    // Red, green, blue; corners 0, 1, 2, 1 (c00, c03, c33, c30).
    let space = "[/Indexed /DeviceRGB 2 <FF0000 00FF00 0000FF>]";
    let fill = read_one(&one_component_shading(space, "0 255"), [0, 1, 2, 1], vec![]).unwrap();
    let (p, at) = (&fill.patches[0], |u, v| {
        fill.srgb_at(&fill.patches[0], u, v)
    });
    assert_eq!(p.components, vec![0.0, 1.0, 1.0, 2.0]);
    assert_near(at(0.0, 0.0), [1.0, 0.0, 0.0]);
    assert_near(at(1.0, 1.0), [0.0, 0.0, 1.0]);
    // The index is bilinear and rounded: 0.25 is entry 0, 0.5 and the centre's 1 entry 1.
    assert_near(at(0.0, 0.25), [1.0, 0.0, 0.0]);
    assert_near(at(0.0, 0.5), [0.0, 1.0, 0.0]);
    assert_near(at(0.5, 0.5), [0.0, 1.0, 0.0]);
    // An index past hival is the last entry.
    let fill = read_one(&one_component_shading(space, "0 255"), [9, 9, 9, 9], vec![]).unwrap();
    assert_near(fill.srgb_at(&fill.patches[0], 0.5, 0.5), [0.0, 0.0, 1.0]);
}

#[test]
fn an_indexed_lookup_stream_over_lab_takes_the_base_ranges() {
    // Two Lab entries: bytes (255, 128, 128) and (0, 0, 255) over L 0..100, a and b -128..127.
    let lab = "[/Lab << /WhitePoint [0.95047 1 1.08883] /Range [-128 127 -128 127] >>]";
    let space = format!("[/Indexed {lab} 1 7 0 R]");
    let table = stream("", &[255, 128, 128, 0, 0, 255]);
    let fill = read_one(
        &one_component_shading(&space, "0 255"),
        [0, 0, 1, 1],
        vec![table],
    );
    let fill = fill.unwrap();
    let PdfColourSpace::Indexed { lookup, .. } = &fill.colour.space else {
        panic!("{:?}", fill.colour.space)
    };
    assert_eq!(*lookup, [100.0, 0.0, 0.0, 0.0, -128.0, 127.0]);
    // Entry 0 is Lab white.
    let white = fill.srgb_at(&fill.patches[0], 0.0, 0.0);
    assert!(white.iter().all(|c| (c - 1.0).abs() < 1e-3), "{white:?}");
}

#[test]
fn bad_indexed_spaces_are_errors_naming_the_object() {
    let cases = [
        ("[/Indexed /DeviceRGB 2 <FF0000 00FF00>]", "holds 6 bytes"),
        ("[/Indexed /DeviceRGB 300 <FF>]", "hival 300"),
        ("[/Indexed /DeviceRGB 1.5 <FF>]", "hival 1.5"),
        ("[/Indexed /DeviceRGB 0]", "4 entries"),
        (
            "[/Indexed [/Indexed /DeviceRGB 0 <000000>] 0 <00>]",
            "base of an Indexed",
        ),
        ("[/Indexed /DeviceRGB 0 12]", "string or a stream"),
    ];
    for (space, reason) in cases {
        let e = read_one(&one_component_shading(space, "0 255"), [0; 4], vec![]).unwrap_err();
        assert!(
            e.contains("object 5 /ColorSpace") && e.contains(reason),
            "{space}: {e}"
        );
    }
    // A space whose base is itself: nesting is bounded.
    let dict = one_component_shading("7 0 R", "0 255");
    let looped = b"[/Indexed 7 0 R 0 <00>]".to_vec();
    let e = read_one(&dict, [0; 4], vec![looped]).unwrap_err();
    assert!(e.contains("nest deeper than"), "{e}");
}

/// A type 4 function of `inputs` inputs (`Domain` [0 1] each) and `outputs` outputs
/// ([0 1] each) running `program`.
fn postscript_function(inputs: usize, outputs: usize, program: &str) -> Vec<u8> {
    let dict = format!(
        "/FunctionType 4 /Domain [{}] /Range [{}]",
        "0 1 ".repeat(inputs),
        "0 1 ".repeat(outputs)
    );
    stream(&dict, program.as_bytes())
}

#[test]
fn a_separation_through_a_type_4_tint_transform() {
    // tint t -> CMYK (0, t, t / 2, 0) -> RGB (1, 1 - t, 1 - t / 2), naively.
    let tint = postscript_function(1, 4, "{ 0 exch dup 0.5 mul 0 }");
    let space = "[/Separation /Spot /DeviceCMYK 7 0 R]";
    let dict = one_component_shading(space, "0 1");
    let fill = read_one(&dict, [0, 51, 255, 102], vec![tint]).unwrap();
    let at = |u, v| fill.srgb_at(&fill.patches[0], u, v);
    let expected = |t: f64| [1.0, 1.0 - t, 1.0 - t / 2.0];
    assert_near(at(0.0, 0.0), expected(0.0));
    assert_near(at(0.0, 1.0), expected(0.2));
    assert_near(at(1.0, 1.0), expected(1.0));
    assert_near(at(1.0, 0.0), expected(0.4));
    // The centre's tint is the corners' mean, 0.4.
    assert_near(at(0.5, 0.5), expected(0.4));
}

#[test]
fn a_device_n_space_of_two_colourants() {
    // (a, b) -> RGB (a, b, (a + b) / 2); two components a corner.
    let tint = postscript_function(2, 3, "{ 2 copy add 2 div }");
    let space = "[/DeviceN [/A /B] /DeviceRGB 7 0 R]";
    let dict = format!(
        "/ShadingType 6 /ColorSpace {space} /BitsPerCoordinate 8 /BitsPerComponent 8 \
         /BitsPerFlag 8 /Decode [0 255 0 255 0 1 0 1]"
    );
    let mut record = coons_record()[..25].to_vec();
    record.extend([0, 0, 255, 0, 255, 255, 0, 255]);
    let file = page_with("/S0 sh", stream(&dict, &record), vec![tint]);
    let picture = read_pdf(&file, 1, &Limits::DEFAULT).unwrap();
    let fill = &picture.fills[0];
    let at = |u, v| fill.srgb_at(&fill.patches[0], u, v);
    assert_near(at(0.0, 0.0), [0.0, 0.0, 0.0]);
    assert_near(at(0.0, 1.0), [1.0, 0.0, 0.5]);
    assert_near(at(1.0, 1.0), [1.0, 1.0, 1.0]);
    assert_near(at(0.5, 0.5), [0.5, 0.5, 0.5]);
}

#[test]
fn bad_tint_transforms_are_errors_naming_the_object() {
    let dict = one_component_shading("[/Separation /Spot /DeviceRGB 7 0 R]", "0 1");
    let cases = [
        (
            postscript_function(1, 3, "{ 1 exch div dup dup }"),
            "fails at the inputs [0.0]",
        ),
        (
            postscript_function(1, 3, "{ dup dup moveto }"),
            "moveto is not an operator",
        ),
        (
            postscript_function(2, 3, "{ pop dup dup }"),
            "1 input (a Domain of 2 numbers)",
        ),
        (
            stream("/FunctionType 4 /Domain [0 1]", b"{ dup dup }"),
            "has no Range",
        ),
    ];
    for (function, reason) in cases {
        let e = read_one(&dict, [0; 4], vec![function]).unwrap_err();
        assert!(
            e.contains("object 5 /ColorSpace (the Separation tint transform)")
                && e.contains(reason),
            "{reason}: {e}"
        );
    }
    let dict = one_component_shading("[/DeviceN [/A /B] /DeviceRGB 7 0 R]", "0 1 0 1");
    let exponential = b"<< /FunctionType 2 /Domain [0 1 0 1] /C1 [1 1 1] /N 1 >>".to_vec();
    let e = read_one(&dict, [0; 4], vec![exponential]).unwrap_err();
    assert!(
        e.contains("FunctionType 2 has one input by definition")
            && e.contains("2 colourants need a function of type 0 or 4"),
        "{e}"
    );
    let stitching = b"<< /FunctionType 3 /Domain [0 1 0 1] /Functions [] >>".to_vec();
    let e = read_one(&dict, [0; 4], vec![stitching]).unwrap_err();
    assert!(
        e.contains("FunctionType 3 has one input by definition"),
        "{e}"
    );
    // A sampled tint transform of more inputs than are interpolated.
    let names = "/A /B /C /D /E /F /G /H /I";
    let sampled = stream(
        &format!(
            "/FunctionType 0 /Domain [{}] /Range [0 1] /Size [{}] /BitsPerSample 8",
            "0 1 ".repeat(9),
            "1 ".repeat(9)
        ),
        &[0],
    );
    let e = read_one(
        &device_n_shading(names, "/DeviceGray"),
        [0; 4],
        vec![sampled],
    )
    .unwrap_err();
    assert!(
        e.contains("a sampled function of 9 inputs is not read (at most 8)"),
        "{e}"
    );
}

/// A page of 300 x 200 points painting the patch of [`coons_record`] with `sh`, `/Rotate`
/// given by the page tree's root (inherited) and, when `on_page` is some, by the page.
fn rotated_page(inherited: i32, on_page: Option<&str>) -> PdfPicture {
    let page = format!(
        "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 300 200] /Contents 4 0 R /Resources << /Shading << /S0 5 0 R >> >> {} >>",
        on_page.map(|r| format!("/Rotate {r}")).unwrap_or_default()
    );
    let objects = [
        b"<< /Type /Catalog /Pages 2 0 R >>".to_vec(),
        format!("<< /Type /Pages /Kids [3 0 R] /Count 1 /Rotate {inherited} >>").into_bytes(),
        page.into_bytes(),
        stream("", b"/S0 sh"),
        stream(SHADING_DICT, &coons_record()),
    ];
    read_pdf(&pdf_file(&objects, ""), 1, &Limits::DEFAULT).unwrap()
}

/// `/Rotate` inherited, on the page, the rotation read, the view, and three corners.
type RotationCase<'a> = (i32, Option<&'a str>, u16, Rect, [Point; 3]);

#[test]
fn rotate_turns_the_picture_clockwise() {
    // Shading points (0, 0), (0, 255) and (255, 0): upright at (0, 200), (0, -55), (255, 200).
    let corners = |p: &PdfPicture| {
        let q = &p.fills[0].patches[0].points;
        [q[0][0], q[0][3], q[3][0]]
    };
    let cases: [RotationCase; 5] = [
        (
            0,
            None,
            0,
            Rect::new(0.0, 0.0, 300.0, 200.0),
            [
                Point::new(0.0, 200.0),
                Point::new(0.0, -55.0),
                Point::new(255.0, 200.0),
            ],
        ),
        // A quarter clockwise: (x, y) to (200 - y, x).
        (
            90,
            None,
            90,
            Rect::new(0.0, 0.0, 200.0, 300.0),
            [
                Point::new(0.0, 0.0),
                Point::new(255.0, 0.0),
                Point::new(0.0, 255.0),
            ],
        ),
        // The page's own entry wins over the inherited one: (x, y) to (300 - x, 200 - y).
        (
            90,
            Some("180"),
            180,
            Rect::new(0.0, 0.0, 300.0, 200.0),
            [
                Point::new(300.0, 0.0),
                Point::new(300.0, 255.0),
                Point::new(45.0, 0.0),
            ],
        ),
        // -90 is 270: (x, y) to (y, 300 - x).
        (
            -90,
            None,
            270,
            Rect::new(0.0, 0.0, 200.0, 300.0),
            [
                Point::new(200.0, 300.0),
                Point::new(-55.0, 300.0),
                Point::new(200.0, 45.0),
            ],
        ),
        (
            0,
            Some("450"),
            90,
            Rect::new(0.0, 0.0, 200.0, 300.0),
            [
                Point::new(0.0, 0.0),
                Point::new(255.0, 0.0),
                Point::new(0.0, 255.0),
            ],
        ),
    ];
    for (inherited, on_page, rotation, view, points) in cases {
        let picture = rotated_page(inherited, on_page);
        assert_eq!(picture.rotation, rotation, "{inherited} {on_page:?}");
        assert_eq!(picture.view_rect(), view, "{inherited} {on_page:?}");
        assert_eq!(corners(&picture), points, "{inherited} {on_page:?}");
        assert!(picture.warnings.is_empty(), "{:?}", picture.warnings);
    }
    let picture = rotated_page(0, Some("45"));
    assert_eq!(picture.rotation, 0);
    assert!(picture
        .warnings
        .iter()
        .any(|w| w.contains("/Rotate 45 is not a multiple of 90")));
}

/// A shading dictionary of the DeviceN space `[/DeviceN [names] alternate 7 0 R]` with one
/// 8-bit component a colourant decoded to 0..1, over [`coons_record`]'s patch.
fn device_n_shading(names: &str, alternate: &str) -> String {
    let count = names.split_whitespace().count();
    format!(
        "/ShadingType 6 /ColorSpace [/DeviceN [{names}] {alternate} 7 0 R] \
         /BitsPerCoordinate 8 /BitsPerComponent 8 /BitsPerFlag 8 /Decode [0 255 0 255 {}]",
        "0 1 ".repeat(count)
    )
}

/// The tint transform of `fill`, a `Tinted` space, at `tints`, in sRGB.
fn tinted_srgb(fill: &ShadingFill, tints: &[f64]) -> [f64; 3] {
    fill.colour.space.to_srgb(tints)
}

#[test]
fn a_device_n_space_through_a_sampled_tint_transform_of_two_inputs() {
    // Size [2 2], the first input varying fastest: (0, 0) black, (1, 0) red, (0, 1) blue,
    // (1, 1) white.
    let samples = [0, 0, 0, 255, 0, 0, 0, 0, 255, 255, 255, 255];
    let tint = stream(
        "/FunctionType 0 /Domain [0 1 0 1] /Range [0 1 0 1 0 1] /Size [2 2] /BitsPerSample 8",
        &samples,
    );
    let dict = device_n_shading("/A /B", "/DeviceRGB");
    let mut record = coons_record()[..25].to_vec();
    // c00 (0, 0), c03 (1, 0), c33 (1, 1), c30 (0, 1).
    record.extend([0, 0, 255, 0, 255, 255, 0, 255]);
    let file = page_with("/S0 sh", stream(&dict, &record), vec![tint]);
    let picture = read_pdf(&file, 1, &Limits::DEFAULT).unwrap();
    let fill = &picture.fills[0];
    let at = |u, v| fill.srgb_at(&fill.patches[0], u, v);
    assert_near(at(0.0, 0.0), [0.0, 0.0, 0.0]);
    assert_near(at(0.0, 1.0), [1.0, 0.0, 0.0]);
    assert_near(at(1.0, 1.0), [1.0, 1.0, 1.0]);
    // Tints (0.5, 0): half way from black to red.
    assert_near(at(0.0, 0.5), [0.5, 0.0, 0.0]);
    // Tints (0.5, 0.5): the mean of the four samples.
    assert_near(at(0.5, 0.5), [0.5, 0.25, 0.5]);
    // Tints (0.5, 1): half way from blue to white.
    assert_near(at(1.0, 0.5), [0.5, 0.5, 1.0]);
}

#[test]
fn a_sampled_tint_transform_steps_through_an_uneven_grid() {
    // Size [3 2] into grey: (i, j) = (0, 0) 0, (1, 0) 1, (2, 0) 0, (0, 1) 0.2, (1, 1) 0.4,
    // (2, 1) 1.
    let mut record = coons_record()[..25].to_vec();
    record.extend([0; 8]);
    let tint = stream(
        "/FunctionType 0 /Domain [0 1 0 1] /Range [0 1] /Size [3 2] /BitsPerSample 8",
        &[0, 255, 0, 51, 102, 255],
    );
    let dict = device_n_shading("/A /B", "/DeviceGray");
    let file = page_with("/S0 sh", stream(&dict, &record), vec![tint]);
    let picture = read_pdf(&file, 1, &Limits::DEFAULT).unwrap();
    let fill = &picture.fills[0];
    let grey = |g: f64| [g, g, g];
    assert_near(tinted_srgb(fill, &[0.5, 0.0]), grey(1.0));
    assert_near(tinted_srgb(fill, &[1.0, 1.0]), grey(1.0));
    assert_near(tinted_srgb(fill, &[0.5, 1.0]), grey(0.4));
    // a = 0.75 is half way between the samples 1 and 2; b = 0.5 half way between rows: the
    // mean of 1, 0, 0.4 and 1.
    assert_near(tinted_srgb(fill, &[0.75, 0.5]), grey(0.6));
    // b = 0.25 along a = 0: 0.25 of the way from 0 to 0.2.
    assert_near(tinted_srgb(fill, &[0.0, 0.25]), grey(0.05));
}

#[test]
fn an_array_of_type_4_functions_of_two_inputs_gives_an_output_each() {
    // (a, b) -> RGB ((a + b) / 2, a, b).
    let functions = [
        postscript_function(2, 1, "{ add 2 div }"),
        postscript_function(2, 1, "{ pop }"),
        postscript_function(2, 1, "{ exch pop }"),
    ];
    let mut objects = vec![b"[8 0 R 9 0 R 10 0 R]".to_vec()];
    objects.extend(functions);
    let mut record = coons_record()[..25].to_vec();
    record.extend([0; 8]);
    let dict = device_n_shading("/A /B", "/DeviceRGB");
    let file = page_with("/S0 sh", stream(&dict, &record), objects);
    let picture = read_pdf(&file, 1, &Limits::DEFAULT).unwrap();
    assert_near(tinted_srgb(&picture.fills[0], &[0.2, 0.6]), [0.4, 0.2, 0.6]);
}

#[test]
fn the_background_fills_a_pattern_fill_and_is_ignored_by_sh() {
    let with_background = |extra: &str| {
        let dict = format!("{SHADING_DICT} /Background [1 0 0] {extra}");
        stream(&dict, &coons_record())
    };
    let fill_page = "/Pattern cs /P0 scn 0 0 300 200 re f";
    let picture = read_pdf(
        &page_with(fill_page, with_background(""), vec![]),
        1,
        &Limits::DEFAULT,
    )
    .unwrap();
    assert_eq!(picture.fills.len(), 2);
    let background = &picture.fills[0];
    assert_eq!(background.object, "object 5 /Background");
    assert_eq!(
        background.control_bounds(),
        Rect::new(0.0, 0.0, 300.0, 200.0)
    );
    assert_near(
        background.srgb_at(&background.patches[0], 0.5, 0.5),
        [1.0, 0.0, 0.0],
    );
    assert_eq!(picture.fills[1].object, "object 5");
    // Within the BBox, [0 0 100 100] in pattern space, moved by the pattern's Matrix to
    // (10, 20)-(110, 120) on the page, y down in the picture of 200 points.
    let picture = read_pdf(
        &page_with(fill_page, with_background("/BBox [0 0 100 100]"), vec![]),
        1,
        &Limits::DEFAULT,
    )
    .unwrap();
    let bounds = picture.fills[0].control_bounds();
    assert!(
        (bounds.x0 - 10.0).abs() < 1e-9 && (bounds.x1 - 110.0).abs() < 1e-9,
        "{bounds:?}"
    );
    assert!(
        (bounds.y0 - 80.0).abs() < 1e-9 && (bounds.y1 - 180.0).abs() < 1e-9,
        "{bounds:?}"
    );
    // sh paints the shading alone.
    let picture = read_pdf(
        &page_with("/S0 sh", with_background(""), vec![]),
        1,
        &Limits::DEFAULT,
    )
    .unwrap();
    assert_eq!(picture.fills.len(), 1);
    // A Background of the wrong length is left out, with a warning naming it.
    let picture = read_pdf(
        &page_with(
            fill_page,
            stream(
                &format!("{SHADING_DICT} /Background [1 0]"),
                &coons_record(),
            ),
            vec![],
        ),
        1,
        &Limits::DEFAULT,
    )
    .unwrap();
    assert_eq!(picture.fills.len(), 1);
    assert!(
        picture
            .warnings
            .iter()
            .any(|w| w.contains("object 5 /Background has 2 numbers")),
        "{:?}",
        picture.warnings
    );
}

#[test]
fn a_blend_mode_other_than_normal_is_named_in_a_warning() {
    let page = |mode: &str| {
        let objects = vec![
            b"<< /Type /Catalog /Pages 2 0 R >>".to_vec(),
            b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_vec(),
            b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 300 200] /Contents 4 0 R /Resources << /Shading << /S0 5 0 R >> /ExtGState << /G0 6 0 R >> >> >>".to_vec(),
            stream("", b"/G0 gs /S0 sh"),
            stream(SHADING_DICT, &coons_record()),
            format!("<< /Type /ExtGState /BM {mode} >>").into_bytes(),
        ];
        read_pdf(&pdf_file(&objects, ""), 1, &Limits::DEFAULT).unwrap()
    };
    let screen = page("/Screen");
    assert!(
        screen
            .warnings
            .iter()
            .any(|w| w.contains("object 6: the blend mode Screen is not applied")),
        "{:?}",
        screen.warnings
    );
    assert!(page("[/Multiply /Normal]")
        .warnings
        .iter()
        .any(|w| w.contains("Multiply")));
    assert!(page("/Normal")
        .warnings
        .iter()
        .all(|w| !w.contains("blend mode")));
}
