//! Saving through the API: the state the page is told after a save, and the refusal (409,
//! `code: "file_exists"`) to replace a file the session did not write unless the request says
//! `overwrite: true`.

use std::path::{Path, PathBuf};

use gradmesh_serve::{start, Config, Running};
use serde_json::Value;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

const SQUARE: &str = r##"{"format":"gradmesh","version":1,"layers":[{"name":"square","points":[
  {"position":[0,0],"colour":"#d04020"},{"position":[100,0],"colour":"#e0c030"},
  {"position":[100,100],"colour":"#2060c0"},{"position":[0,100],"colour":"#40a040"}],
  "faces":[[0,1,2,3]]}]}"##;

/// A file of the paper authors' artwork in `../shared`, or a clear failure.
fn shared_off(name: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/realdata/gradientmeshimproved-off")
        .join(name);
    assert!(
        path.is_file(),
        "the test needs {} (the shared data beside the repository)",
        path.display()
    );
    path
}

async fn serve(file: Option<PathBuf>, folder: &Path) -> Running {
    start(&Config {
        file,
        folder: Some(folder.to_path_buf()),
        ..Config::default()
    })
    .await
    .unwrap()
}

/// POSTs a command; the status and the answer's JSON.
async fn command(running: &Running, json: &str) -> (u16, Value) {
    let mut stream = TcpStream::connect(running.address).await.unwrap();
    let head = format!(
        "POST /api/command?token={} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nConnection: close\r\n\
         Content-Type: application/json\r\nContent-Length: {}\r\n\r\n",
        running.token,
        running.address.port(),
        json.len()
    );
    stream.write_all(head.as_bytes()).await.unwrap();
    stream.write_all(json.as_bytes()).await.unwrap();
    let mut answer = Vec::new();
    stream.read_to_end(&mut answer).await.unwrap();
    let text = String::from_utf8_lossy(&answer).to_string();
    let status = text.split(' ').nth(1).and_then(|s| s.parse().ok());
    let status = status.unwrap_or_else(|| panic!("no HTTP answer: {text:?}"));
    let body = text.split_once("\r\n\r\n").map(|(_, b)| b).unwrap_or("");
    let value = serde_json::from_str(body).unwrap_or(Value::String(body.to_string()));
    (status, value)
}

fn move_point(dx: f64) -> String {
    format!(
        r#"{{"type":"edit","op":{{"op":"move_points","layer":0,"points":[0],"dx":{dx},"dy":0}}}}"#
    )
}

fn first_x(path: &Path) -> f64 {
    let doc = gradmesh::formats::read_path(path).unwrap();
    doc.layers[0].points[0].position.x
}

fn assert_refused_as_existing(status: u16, answer: &Value) {
    assert_eq!(status, 409, "{answer}");
    assert_eq!(answer["code"], "file_exists", "{answer}");
    assert!(
        answer["message"].as_str().unwrap().contains("exists"),
        "{answer}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn saving_a_document_opened_from_off_asks_before_replacing_its_json() {
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("Tucan.off");
    std::fs::copy(shared_off("Tucan_Tucan_Layer0.off"), &off).unwrap();
    let json = dir.path().join("Tucan.json");
    std::fs::write(&json, SQUARE).unwrap();
    let running = serve(Some(off), dir.path()).await;
    assert_eq!(command(&running, &move_point(7.0)).await.0, 200);

    let (status, answer) = command(&running, r#"{"type":"save"}"#).await;
    assert_refused_as_existing(status, &answer);
    assert_eq!(std::fs::read_to_string(&json).unwrap(), SQUARE, "untouched");

    let (status, state) = command(&running, r#"{"type":"save","overwrite":true}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["modified"], false, "{state}");
    assert_eq!(state["file"], "Tucan.json");
    assert_eq!(state["saved"]["file"], "Tucan.json", "{state}");
    assert!(state["saved"]["at"].as_u64().unwrap() > 1_600_000_000_000);
    let saved = gradmesh::formats::read_path(&json).unwrap();
    assert_eq!(saved.layers[0].points.len(), 12, "the Tucan's layer");

    // The session wrote it: the next save does not ask.
    assert_eq!(command(&running, &move_point(1.0)).await.0, 200);
    let (status, state) = command(&running, r#"{"type":"save"}"#).await;
    assert_eq!((status, &state["modified"]), (200, &Value::Bool(false)));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_document_opened_from_off_saves_without_asking_when_its_json_is_new() {
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("Tucan.off");
    std::fs::copy(shared_off("Tucan_Tucan_Layer0.off"), &off).unwrap();
    let running = serve(Some(off), dir.path()).await;
    let (status, state) = command(&running, r#"{"type":"save"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert!(dir.path().join("Tucan.json").is_file());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn save_as_onto_an_existing_name_asks_and_a_json_opened_saves_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let square = dir.path().join("square.json");
    std::fs::write(&square, SQUARE).unwrap();
    let other = dir.path().join("other.json");
    std::fs::write(&other, SQUARE).unwrap();
    let running = serve(Some(square.clone()), dir.path()).await;
    assert_eq!(command(&running, &move_point(5.0)).await.0, 200);

    // The JSON opened is the document's own file: saved in place.
    let (status, state) = command(&running, r#"{"type":"save"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(first_x(&square), 5.0);

    // Save as onto a file the session did not write: refused until asked with overwrite.
    let onto_other = r#"{"type":"save_as","name":"other.json"}"#;
    let (status, answer) = command(&running, onto_other).await;
    assert_refused_as_existing(status, &answer);
    assert_eq!(std::fs::read_to_string(&other).unwrap(), SQUARE);
    let state = command(&running, r#"{"type":"state"}"#).await.1;
    assert_eq!(
        state["file"], "square.json",
        "a refused save changes nothing"
    );
    let overwrite = r#"{"type":"save_as","name":"other.json","overwrite":true}"#;
    let (status, state) = command(&running, overwrite).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(
        (first_x(&other), &state["file"]),
        (5.0, &"other.json".into())
    );

    // Save as to a new name, then onto it again: the session wrote it, no question.
    let fresh = r#"{"type":"save_as","name":"fresh.json"}"#;
    assert_eq!(command(&running, fresh).await.0, 200);
    assert_eq!(command(&running, &move_point(2.0)).await.0, 200);
    let (status, state) = command(&running, fresh).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(first_x(&dir.path().join("fresh.json")), 7.0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_json_opened_from_the_menu_saves_in_place_and_new_forgets_the_last_save() {
    let dir = tempfile::tempdir().unwrap();
    let other = dir.path().join("other.json");
    std::fs::write(&other, SQUARE).unwrap();
    let running = serve(None, dir.path()).await;
    let (status, state) = command(&running, r#"{"type":"open","name":"other.json"}"#).await;
    assert_eq!((status, &state["saved"]), (200, &Value::Null), "{state}");
    assert_eq!(command(&running, &move_point(3.0)).await.0, 200);
    let (status, state) = command(&running, r#"{"type":"save"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["saved"]["file"], "other.json");
    assert_eq!(first_x(&other), 3.0);
    let (_, state) = command(&running, r#"{"type":"new"}"#).await;
    assert_eq!(
        (&state["file"], &state["saved"]),
        (&Value::Null, &Value::Null)
    );
}

async fn get(running: &Running, target: &str) -> (u16, Vec<u8>, String) {
    let mut stream = TcpStream::connect(running.address).await.unwrap();
    let head = format!(
        "GET {target}&token={} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nConnection: close\r\n\r\n",
        running.token,
        running.address.port(),
    );
    stream.write_all(head.as_bytes()).await.unwrap();
    let mut answer = Vec::new();
    stream.read_to_end(&mut answer).await.unwrap();
    let split = answer.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&answer[..split]).to_string();
    let status = head.split(' ').nth(1).unwrap().parse().unwrap();
    (status, answer[split + 4..].to_vec(), head)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn exports_are_named_after_the_document_in_each_format() {
    let dir = tempfile::tempdir().unwrap();
    let square = dir.path().join("square.json");
    std::fs::write(&square, SQUARE).unwrap();
    let running = serve(Some(square), dir.path()).await;
    for (format, magic, kind) in [
        ("png", &b"\x89PNG"[..], "image/png"),
        ("pdf", &b"%PDF-"[..], "application/pdf"),
        ("svg", &b"<svg"[..], "image/svg+xml"),
    ] {
        let (status, body, head) =
            get(&running, &format!("/api/export?format={format}&size=300")).await;
        assert_eq!(status, 200, "{format}: {head}");
        assert!(body.starts_with(magic), "{format}");
        assert!(head.contains(kind), "{head}");
        let name = format!("filename=\"square.{format}\"");
        assert!(head.contains(&name), "{head}");
    }
    let (status, png, _) = get(&running, "/api/export?format=png&size=300").await;
    assert_eq!(status, 200);
    // A 300 x 300 image: the width and height of the PNG's header.
    assert_eq!(&png[16..24], &[0, 0, 1, 44, 0, 0, 1, 44]);
    for bad in ["format=gif", "format=png&size=0", "format=pdf&size=99999"] {
        let (status, body, _) = get(&running, &format!("/api/export?{bad}")).await;
        assert!((400..500).contains(&status), "{bad}: {status}");
        assert!(!body.is_empty());
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn layers_come_from_several_files_and_imports_and_faces_are_pasted() {
    let dir = tempfile::tempdir().unwrap();
    let off = dir.path().join("beak.off");
    std::fs::copy(shared_off("Tucan_Tucan_Layer0.off"), &off).unwrap();
    let square = dir.path().join("square.json");
    std::fs::write(&square, SQUARE).unwrap();
    let running = start(&Config {
        file: Some(square.clone()),
        layers_above: vec![off],
        ..Config::default()
    })
    .await
    .unwrap();
    let (_, state) = command(&running, r#"{"type":"state"}"#).await;
    let names: Vec<&str> = (state["layers"].as_array().unwrap().iter())
        .map(|l| l["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["square", "beak"]);
    assert_eq!(state["file"], Value::Null, "several files: Save as");

    let (status, state) =
        command(&running, r#"{"type":"import_layers","name":"square.json"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["layers"].as_array().unwrap().len(), 3);
    assert_eq!(state["can_undo"], true);
    let (status, answer) = command(&running, r#"{"type":"import_layers","name":"../x.off"}"#).await;
    assert_eq!(status, 422, "{answer}");

    // Face 0 of the square pasted into the beak's layer, 200 units right.
    let paste = r#"{"type":"paste","from_layer":0,"faces":[0],"layer":1,"dx":200,"dy":0}"#;
    let (status, state) = command(&running, paste).await;
    assert_eq!(status, 200, "{state}");
    let beak = &state["layers"][1];
    assert_eq!(beak["points"].as_array().unwrap().len(), 16);
    assert_eq!(beak["points"][12], serde_json::json!([200.0, 0.0]));
    assert_eq!(
        beak["hex"][12], "#d04020",
        "the colour follows, in the layer's space"
    );
    let (status, answer) = command(
        &running,
        r#"{"type":"paste","from_layer":0,"faces":[5],"layer":1,"dx":0,"dy":0}"#,
    )
    .await;
    assert_eq!(status, 422, "{answer}");
    command(&running, r#"{"type":"undo"}"#).await;
    let (_, state) = command(&running, r#"{"type":"state"}"#).await;
    assert_eq!(state["layers"][1]["points"].as_array().unwrap().len(), 12);
}

/// A one-page PDF file (300 x 200 points) that writes a line of text and paints one Coons
/// patch over (0, 0)-(255, 255) with `sh`, its corners red, green, blue and white; the
/// cross-reference table is correct.
fn pdf_with_text_and_a_patch() -> Vec<u8> {
    let mut record = vec![0u8];
    let sides: [(u8, u8); 12] = [
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
    record.extend(sides.iter().flat_map(|&(x, y)| [x, y]));
    record.extend([255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]);
    let stream = |dict: &str, data: &[u8]| {
        let mut s = format!("<< {dict} /Length {} >>\nstream\n", data.len()).into_bytes();
        s.extend(data);
        s.extend(b"\nendstream");
        s
    };
    let objects = [
        b"<< /Type /Catalog /Pages 2 0 R >>".to_vec(),
        b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_vec(),
        b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 300 200] /Contents 4 0 R \
           /Resources << /Shading << /S0 5 0 R >> >> >>"
            .to_vec(),
        stream("", b"BT /F1 12 Tf (words) Tj ET /S0 sh"),
        stream(
            "/ShadingType 6 /ColorSpace /DeviceRGB /BitsPerCoordinate 8 /BitsPerComponent 8 \
             /BitsPerFlag 8 /Decode [0 255 0 255 0 1 0 1 0 1]",
            &record,
        ),
    ];
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
    let trailer = format!(
        "trailer\n<< /Size {} /Root 1 0 R >>\nstartxref\n{xref}\n%%EOF\n",
        objects.len() + 1
    );
    out.extend(trailer.as_bytes());
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_pdf_opens_with_its_shadings_as_layers_and_says_what_was_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let pdf = dir.path().join("art.pdf");
    std::fs::write(&pdf, pdf_with_text_and_a_patch()).unwrap();
    let running = serve(Some(pdf), dir.path()).await;
    let (_, state) = command(&running, r#"{"type":"state"}"#).await;
    let layers = state["layers"].as_array().unwrap();
    assert_eq!(layers.len(), 1, "{state}");
    // The patch's corners, y flipped in the 200 pt page: red at (0, 200), white at (255, 200).
    // Their colours are fitted to the page's painting (the file's bilinear RGB is not the
    // scheme's interpolation), so each is nearest its own corner's colour, not equal to it.
    let corners = [
        ((0.0, 200.0), [255, 0, 0]),
        ((0.0, -55.0), [0, 255, 0]),
        ((255.0, -55.0), [0, 0, 255]),
        ((255.0, 200.0), [255, 255, 255]),
    ];
    let nearest_corner = |x: f64, y: f64| {
        let points = layers[0]["points"].as_array().unwrap();
        let k = points.iter().position(|p| *p == serde_json::json!([x, y]));
        let k = k.unwrap_or_else(|| panic!("no point at ({x}, {y}): {points:?}"));
        let hex = layers[0]["hex"][k].as_str().unwrap();
        let rgb: Vec<i64> = (0..3)
            .map(|c| i64::from_str_radix(&hex[1 + 2 * c..3 + 2 * c], 16).unwrap())
            .collect();
        let distance = |to: &[i64; 3]| (0..3).map(|c| (rgb[c] - to[c]).pow(2)).sum::<i64>();
        corners
            .iter()
            .min_by_key(|(_, colour)| distance(colour))
            .map(|(at, _)| *at)
            .unwrap()
    };
    for ((x, y), _) in corners {
        assert_eq!(nearest_corner(x, y), (x, y), "the point at ({x}, {y})");
    }

    let backdrops = state["backdrops"].as_array().unwrap();
    assert_eq!(backdrops.len(), 1, "{state}");
    let message = backdrops[0]["message"].as_str().unwrap();
    assert!(
        message.starts_with("art.pdf: only its patch-mesh shadings are read; left out")
            && message.contains("text is not drawn"),
        "{message}"
    );
    assert_eq!(backdrops[0]["drawn"], false);
    let view = "/api/backdrop.png?width=64&height=64&x0=0&y0=0&x1=300&y1=200";
    assert_eq!(
        get(&running, view).await.0,
        204,
        "nothing of a PDF is drawn"
    );

    // The folder lists it, the menu opens and imports it, and a save writes art.json.
    let (status, body, _) = get(&running, "/api/files?").await;
    assert_eq!(status, 200);
    let names: Vec<String> = serde_json::from_slice(&body).unwrap();
    assert_eq!(names, ["art.pdf"]);
    let (status, state) = command(&running, r#"{"type":"import_layers","name":"art.pdf"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["layers"].as_array().unwrap().len(), 2);
    let (status, state) = command(&running, r#"{"type":"save"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["file"], "art.json");
    let saved = gradmesh::formats::read_path(&dir.path().join("art.json")).unwrap();
    assert_eq!(saved.layers.len(), 2);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_pdf_without_a_patch_mesh_shading_is_refused_with_its_reason() {
    let dir = tempfile::tempdir().unwrap();
    let square = dir.path().join("square.json");
    std::fs::write(&square, SQUARE).unwrap();
    let empty = pdf_with_text_and_a_patch();
    let text = String::from_utf8_lossy(&empty).replace("/S0 sh", "      ");
    std::fs::write(dir.path().join("words.pdf"), text.as_bytes()).unwrap();
    let running = serve(Some(square), dir.path()).await;
    let (status, answer) = command(&running, r#"{"type":"open","name":"words.pdf"}"#).await;
    assert_eq!(status, 422, "{answer}");
    let message = answer["message"].as_str().unwrap();
    assert!(
        message.contains("words.pdf") && message.contains("no shading of type 6 or 7"),
        "{message}"
    );
}

/// A mesh gradient over a blue square: the square is the SVG file's backdrop.
const SQUARE_BEHIND_A_MESH: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200" viewBox="0 0 200 200">
  <meshgradient id="m" gradientUnits="userSpaceOnUse" x="50" y="50">
    <meshrow>
      <meshpatch>
        <stop path="l 100,0" stop-color="#ff4040"/>
        <stop path="l 0,100" stop-color="#ffe060"/>
        <stop path="l -100,0" stop-color="#40a0ff"/>
        <stop path="l 0,-100" stop-color="#8040c0"/>
      </meshpatch>
    </meshrow>
  </meshgradient>
  <rect x="10" y="10" width="180" height="180" fill="#1a2a5a"/>
  <rect x="50" y="50" width="100" height="100" fill="url(#m)"/>
</svg>"##;

/// An imported SVG file's backdrop is part of the import's step: undo takes it away with the
/// layers, redo brings it back.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn undoing_an_import_takes_its_backdrop_away() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("drawing.svg"), SQUARE_BEHIND_A_MESH).unwrap();
    let running = serve(None, dir.path()).await;
    let view = "/api/backdrop.png?width=64&height=64&x0=0&y0=0&x1=200&y1=200";
    let (_, state) = command(&running, r#"{"type":"state"}"#).await;
    let layers = state["layers"].as_array().unwrap().len();
    assert_eq!(state["backdrops"].as_array().unwrap().len(), 0, "{state}");
    assert_eq!(get(&running, view).await.0, 204, "no backdrop yet");

    let (status, state) =
        command(&running, r#"{"type":"import_layers","name":"drawing.svg"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["layers"].as_array().unwrap().len(), layers + 1);
    let backdrops = state["backdrops"].as_array().unwrap();
    assert_eq!(backdrops.len(), 1, "{state}");
    assert_eq!(backdrops[0]["drawn"], true);
    assert_eq!(get(&running, view).await.0, 200, "the square is drawn");

    let (status, state) = command(&running, r#"{"type":"undo"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["layers"].as_array().unwrap().len(), layers);
    assert_eq!(state["backdrops"].as_array().unwrap().len(), 0, "{state}");
    assert_eq!(
        get(&running, view).await.0,
        204,
        "undo took the backdrop away"
    );

    let (status, state) = command(&running, r#"{"type":"redo"}"#).await;
    assert_eq!(status, 200, "{state}");
    assert_eq!(state["backdrops"].as_array().unwrap().len(), 1, "{state}");
    assert_eq!(get(&running, view).await.0, 200, "redo brought it back");
}

/// The paper authors' Glasses exported as SVG (a mesh gradient per patch, finer patches around
/// its irregular points meeting coarser ones at T-junctions) opens again as a few layers: the
/// coarse sides are cut where the finer patches' corners lie, and the rings join the rest.
#[test]
fn an_exported_glasses_opens_again_as_a_few_layers() {
    use gradmesh_serve::exports::{export_document, ExportFormat};
    let doc = gradmesh::formats::read_path(&shared_off("Glasses.off")).unwrap();
    let svg = export_document(&doc, ExportFormat::Svg, 512).expect("the SVG export");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("glasses.svg");
    std::fs::write(&path, svg).unwrap();
    let gradients = gradmesh::formats::read_path(&path).unwrap().layers.len();
    let read = gradmesh_serve::backdrop::read_document(&path).unwrap();
    let layers = read.document.layers.len();
    assert!(gradients > 5000, "{gradients} mesh gradients");
    // Joined without cutting sides at T-junctions, they make 190 layers.
    assert!(
        layers <= 30,
        "{gradients} gradients open as {layers} layers"
    );
}
