//! Warnings about the inputs, gathered while a command runs and printed when it ends: one line
//! per file counting them by kind, or each in full (`--warnings`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use gradmesh::{Warning, WarningKind};

/// The warnings of one command, by the file they are about.
pub struct WarningReport {
    /// Whether every warning is printed, rather than a count per file.
    list: bool,
    /// The files in the order their first warning came, each with its warnings (the layer of
    /// each being the layer in that file). `None`: about no file in particular.
    files: Vec<(Option<PathBuf>, Vec<Warning>)>,
}

impl WarningReport {
    /// An empty report that lists every warning (`list`) or counts them per file.
    pub fn new(list: bool) -> Self {
        WarningReport {
            list,
            files: Vec::new(),
        }
    }

    /// Adds `warnings` about the file at `path` (`None`: about no file in particular).
    pub fn add(&mut self, path: Option<&Path>, warnings: impl IntoIterator<Item = Warning>) {
        let mut warnings = warnings.into_iter().peekable();
        if warnings.peek().is_none() {
            return;
        }
        let index = match self.files.iter().position(|(p, _)| p.as_deref() == path) {
            Some(i) => i,
            None => {
                self.files.push((path.map(Path::to_path_buf), Vec::new()));
                self.files.len() - 1
            }
        };
        self.files[index].1.extend(warnings);
    }

    /// The lines to print, without the `gradmesh: warning: ` prefix; the report is emptied.
    pub fn take_lines(&mut self) -> Vec<String> {
        let mut lines = Vec::new();
        for (path, warnings) in std::mem::take(&mut self.files) {
            let prefix = match &path {
                Some(p) => format!("{}: ", p.display()),
                None => String::new(),
            };
            if self.list {
                lines.extend(warnings.iter().map(|w| format!("{prefix}{w}")));
            } else {
                lines.push(format!(
                    "{prefix}{}: --warnings to list them",
                    summary(&warnings)
                ));
            }
        }
        lines
    }

    /// Prints the warnings gathered so far to standard error, and empties the report.
    pub fn print(&mut self) {
        for line in self.take_lines() {
            eprintln!("gradmesh: warning: {line}");
        }
    }
}

/// `warnings` counted by kind: "3 handles may fold, 1 colour outside sRGB".
fn summary(warnings: &[Warning]) -> String {
    let mut counts: BTreeMap<WarningKind, usize> = BTreeMap::new();
    for w in warnings {
        *counts.entry(w.kind).or_default() += w.count;
    }
    counts
        .into_iter()
        .map(|(kind, n)| kind.counted(n))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn warning(kind: WarningKind, message: &str) -> Warning {
        Warning::new(kind, message)
    }

    #[test]
    fn one_line_per_file_counts_by_kind() {
        let mut report = WarningReport::new(false);
        let (a, b) = (Path::new("a.off"), Path::new("b.off"));
        report.add(Some(a), [warning(WarningKind::HandleMayFold, "h1")]);
        report.add(Some(b), [warning(WarningKind::OutsideGamut, "g1")]);
        report.add(
            Some(a),
            [
                warning(WarningKind::OutsideGamut, "g2"),
                warning(WarningKind::HandleMayFold, "h2"),
                warning(WarningKind::OutsideGamut, "12 more").counting(12),
            ],
        );
        report.add(Some(Path::new("c.off")), []);
        assert_eq!(
            report.take_lines(),
            [
                "a.off: 2 handles may fold, 13 colours outside sRGB: --warnings to list them",
                "b.off: 1 colour outside sRGB: --warnings to list them",
            ]
        );
        assert!(report.take_lines().is_empty());
    }

    #[test]
    fn listing_prints_each_warning_with_its_layer() {
        let mut report = WarningReport::new(true);
        let layered = Warning {
            layer: Some(2),
            ..warning(WarningKind::Fold, "folds here")
        };
        report.add(Some(Path::new("a.json")), [layered]);
        report.add(None, [warning(WarningKind::UnusedPoint, "point 3")]);
        assert_eq!(
            report.take_lines(),
            ["a.json: layer 2: folds here", "point 3"]
        );
    }
}
