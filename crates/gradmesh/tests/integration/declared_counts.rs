//! Enormous declared counts are refused before anything is allocated for them: the peak virtual
//! size of this test process (a process of its own, so that no other test runs beside it), which
//! counts reservations even if never touched, grows by less than a few MB while such headers
//! are read.

use std::time::{Duration, Instant};

use gradmesh::formats::{self, Format};
use gradmesh::ErrorKind;

/// The peak virtual size of this process, in bytes (Linux), if known.
fn peak_virtual_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmPeak:"))?;
    Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
}

/// Set in the process that runs `enormous_declared_counts_allocate_nothing` alone.
const ALONE: &str = "GRADMESH_TEST_ALONE";

/// Runs the test `name` of this module again in a process of its own (the integration tests
/// share one binary, and other tests would allocate beside it) and checks that it passed.
fn run_alone(name: &str) {
    // `module_path!()` starts with the crate's name, which test names leave out.
    let module = module_path!().split_once("::").unwrap().1;
    let test = format!("{module}::{name}");
    let output = std::process::Command::new(std::env::current_exe().unwrap())
        .args([&test, "--exact", "--test-threads=1", "--nocapture"])
        .env(ALONE, &test)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success() && stdout.contains("test result: ok. 1 passed"),
        "{test} in a process of its own:\n{stdout}\n{stderr}"
    );
}

#[test]
fn enormous_declared_counts_allocate_nothing() {
    if std::env::var_os(ALONE).is_none() {
        run_alone("enormous_declared_counts_allocate_nothing");
        return;
    }
    let before = peak_virtual_bytes();
    let start = Instant::now();
    for (text, what) in [
        ("OFF\n1 100000000 0\n", "faces"),
        ("OFF\n100000000 1 0\n", "vertices"),
        // Within the limits, but far more than the file holds: a truncated file.
        ("OFF\n16777216 16777216 0\n", ""),
        (
            "OFF\n3 1 0\n0 0 0 50 0 0 0\n1 0 0 50 0 0 0\n0 1 0 50 0 0 0\n100000000 0 1 2\n",
            "corners",
        ),
    ] {
        let e = formats::read_str(text, Format::Off).unwrap_err();
        if what.is_empty() {
            assert!(e.to_string().contains("unexpected end of file"), "{e}");
        } else {
            assert!(
                matches!(&e.kind, ErrorKind::LimitExceeded { what: w, .. } if w.contains(what)),
                "{e}"
            );
        }
    }
    assert!(
        start.elapsed() < Duration::from_millis(200),
        "{:?}",
        start.elapsed()
    );
    if let (Some(before), Some(after)) = (before, peak_virtual_bytes()) {
        let grown = after.saturating_sub(before);
        assert!(
            grown < 8 << 20,
            "the peak virtual size grew by {grown} bytes"
        );
    }
}
