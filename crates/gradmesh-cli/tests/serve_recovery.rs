//! `gradmesh serve` as a process: edits made through the API survive SIGTERM and SIGKILL in
//! the recovery copy, the next `serve` of the same document offers it (edits refused until
//! the user chooses), restoring gives the document as it was, and a save removes the copy.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::Duration;

use serde_json::Value;

const SQUARE: &str = r##"{"format":"gradmesh","version":1,"layers":[{"name":"square","points":[
  {"position":[0,0],"colour":"#d04020"},{"position":[100,0],"colour":"#e0c030"},
  {"position":[100,100],"colour":"#2060c0"},{"position":[0,100],"colour":"#40a040"}],
  "faces":[[0,1,2,3]]}]}"##;

/// A running `gradmesh serve` and the lines it printed.
struct Served {
    child: Child,
    port: u16,
    token: String,
    lines: Receiver<String>,
    printed: Vec<String>,
}

/// Starts `gradmesh serve ARGS` in `dir` with `state` as the state folder and waits for its
/// URL.
fn serve(args: &[&str], dir: &Path, state: &Path) -> Served {
    let mut child = Command::new(env!("CARGO_BIN_EXE_gradmesh"))
        .arg("serve")
        .args(args)
        .current_dir(dir)
        .env("XDG_STATE_HOME", state)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("gradmesh serve starts");
    let stdout = child.stdout.take().expect("piped");
    let (send, lines) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    let mut served = Served {
        child,
        port: 0,
        token: String::new(),
        lines,
        printed: Vec::new(),
    };
    loop {
        let line = served
            .lines
            .recv_timeout(Duration::from_secs(60))
            .unwrap_or_else(|_| panic!("serve printed no URL; it printed {:?}", served.printed));
        served.printed.push(line.clone());
        if let Some(url) = line.strip_prefix("gradmesh editor: open http://127.0.0.1:") {
            let (port, token) = url.split_once("/?token=").expect("a URL with its token");
            served.port = port.parse().expect("a port");
            served.token = token.to_string();
            return served;
        }
    }
}

/// A server left running by a failed test is ended.
impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Served {
    fn request(&self, method: &str, target: &str, body: &str) -> (u16, String) {
        let mut stream = TcpStream::connect(("127.0.0.1", self.port)).expect("the server answers");
        let join = if target.contains('?') { '&' } else { '?' };
        let head = format!(
            "{method} {target}{join}token={} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nConnection: close\r\n\
             Content-Type: application/json\r\nContent-Length: {}\r\n\r\n",
            self.token,
            self.port,
            body.len()
        );
        stream.write_all(head.as_bytes()).unwrap();
        stream.write_all(body.as_bytes()).unwrap();
        let mut answer = String::new();
        stream.read_to_string(&mut answer).unwrap();
        let status = answer.split(' ').nth(1).and_then(|s| s.parse().ok());
        let body = answer.split_once("\r\n\r\n").map(|(_, b)| b.to_string());
        (status.expect("an HTTP status"), body.unwrap_or_default())
    }

    fn command(&self, json: &str) -> (u16, Value) {
        let (status, body) = self.request("POST", "/api/command", json);
        let value = serde_json::from_str(&body).unwrap_or(Value::String(body));
        (status, value)
    }

    /// The document as JSON text.
    fn document(&self) -> String {
        let (status, text) = self.request("GET", "/api/document.json", "");
        assert_eq!(status, 200, "{text}");
        text
    }

    /// Sends `signal` (TERM or KILL), waits for the end; returns the exit's success and what
    /// the server printed.
    fn stop(mut self, signal: &str) -> (bool, Vec<String>) {
        let killed = Command::new("kill")
            .arg(format!("-{signal}"))
            .arg(self.child.id().to_string())
            .status()
            .expect("kill runs");
        assert!(killed.success());
        let status = self.child.wait().unwrap();
        let rest: Vec<String> = self.lines.iter().collect();
        self.printed.extend(rest);
        (status.success(), std::mem::take(&mut self.printed))
    }
}

fn edit(op: &str) -> String {
    format!(r#"{{"type":"edit","op":{op}}}"#)
}

#[test]
fn sigterm_keeps_the_unsaved_edits_and_the_next_serve_restores_them() {
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("square.json"), SQUARE).unwrap();
    let served = serve(&["square.json"], dir.path(), state.path());
    for op in [
        r#"{"op":"move_points","layer":0,"points":[0],"dx":5,"dy":-3}"#,
        r##"{"op":"set_colour","layer":0,"points":[2],"css":"#ff00ff"}"##,
        r#"{"op":"add_layer","name":"top"}"#,
        r#"{"op":"add_rectangle","layer":1,"rect":[10,10,60,40]}"#,
    ] {
        let (status, answer) = served.command(&edit(op));
        assert_eq!(status, 200, "{op}: {answer}");
    }
    // A drag still under way (its gesture not ended) when the signal comes.
    let drag = r#"{"type":"edit","gesture":4,"op":{"op":"move_points","layer":1,"points":[0],"dx":2,"dy":2}}"#;
    assert_eq!(served.command(drag).0, 200);
    let edited = served.document();

    let (clean, printed) = served.stop("TERM");
    assert!(clean, "serve ends cleanly on SIGTERM: {printed:?}");
    let copy = dir.path().join(".square.json.recover");
    let said = printed.join("\n");
    assert!(
        said.contains("unsaved edits") && said.contains(&copy.display().to_string()),
        "serve says where the edits are: {said}"
    );
    assert!(copy.is_file());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("square.json")).unwrap(),
        SQUARE
    );

    let served = serve(&["square.json"], dir.path(), state.path());
    assert!(
        served.printed.join("\n").contains(".square.json.recover"),
        "{:?}",
        served.printed
    );
    let (_, offered) = served.command(r#"{"type":"state"}"#);
    assert!(offered["recovery"]["file"]
        .as_str()
        .unwrap()
        .ends_with(".square.json.recover"));
    let (status, refused) = served.command(&edit(
        r#"{"op":"move_points","layer":0,"points":[0],"dx":1,"dy":0}"#,
    ));
    assert_eq!(
        (status, &refused["code"]),
        (409, &Value::from("recovery_pending"))
    );

    let (status, restored) = served.command(r#"{"type":"recovery","restore":true}"#);
    assert_eq!(status, 200, "{restored}");
    assert_eq!(restored["recovery"], Value::Null);
    assert_eq!(restored["modified"], true);
    assert_eq!(
        served.document(),
        edited,
        "the restored document is the edited one"
    );
    // One undo step goes back to the file.
    served.command(r#"{"type":"undo"}"#);
    let file = gradmesh::formats::json::write_document(
        &gradmesh::formats::read_path(&dir.path().join("square.json")).unwrap(),
    );
    assert_eq!(served.document(), file);
    served.command(r#"{"type":"redo"}"#);

    let (status, saved) = served.command(r#"{"type":"save"}"#);
    assert_eq!(
        (status, &saved["modified"]),
        (200, &Value::Bool(false)),
        "{saved}"
    );
    assert!(!copy.exists(), "a save removes the copy");
    let (clean, printed) = served.stop("TERM");
    assert!(clean);
    assert!(
        printed.join("\n").contains("nothing was left unsaved"),
        "{printed:?}"
    );
    let on_disk = gradmesh::formats::read_path(&dir.path().join("square.json")).unwrap();
    assert_eq!(gradmesh::formats::json::write_document(&on_disk), edited);
}

/// The recovery copies in the state folder.
fn copies_in(state: &Path) -> Vec<PathBuf> {
    match std::fs::read_dir(state.join("gradmesh")) {
        Ok(entries) => entries.map(|e| e.unwrap().path()).collect(),
        Err(_) => Vec::new(),
    }
}

#[test]
fn sigkill_leaves_the_copy_of_a_new_document_and_discard_removes_it() {
    let dir = tempfile::tempdir().unwrap();
    let state = tempfile::tempdir().unwrap();
    let served = serve(&[], dir.path(), state.path());
    let rectangle = r#"{"op":"add_rectangle","layer":0,"rect":[0,0,40,30]}"#;
    assert_eq!(served.command(&edit(rectangle)).0, 200);
    let edited = served.document();
    let (clean, _) = served.stop("KILL");
    assert!(!clean);
    let copies = copies_in(state.path());
    assert_eq!(copies.len(), 1, "{copies:?}");
    let name = copies[0].file_name().unwrap().to_string_lossy().to_string();
    assert!(
        name.starts_with("untitled-") && name.ends_with(".json.recover"),
        "{name}"
    );

    // Restored, then the server killed again before anything else: the copy is still there.
    let served = serve(&[], dir.path(), state.path());
    let (status, _) = served.command(r#"{"type":"recovery","restore":true}"#);
    assert_eq!(status, 200);
    assert_eq!(served.document(), edited);
    served.stop("KILL");
    assert_eq!(copies_in(state.path()).len(), 1);

    let served = serve(&[], dir.path(), state.path());
    let (status, state_now) = served.command(r#"{"type":"recovery","restore":false}"#);
    assert_eq!(status, 200, "{state_now}");
    assert!(
        copies_in(state.path()).is_empty(),
        "discard removes the copy"
    );
    assert_eq!(state_now["layers"][0]["points"], Value::Array(vec![]));
    assert_eq!(served.command(&edit(rectangle)).0, 200, "edits go on");
    served.stop("TERM");
}
