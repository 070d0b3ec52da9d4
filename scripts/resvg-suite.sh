#!/usr/bin/env bash
# resvg's regression suite through gradmesh's whole-picture path (docs/svg.md, "resvg's test
# suite"): every test SVG of linebender/resvg with an invisible mesh fill added, rendered by
# `gradmesh render` at its reference PNG's size; prints the exit statuses and the share of
# renders that match the reference, by area, and the same for resvg itself.
#
# usage: scripts/resvg-suite.sh [RESVG_CHECKOUT] [OUT_DIR]
#   RESVG_CHECKOUT: a clone of https://github.com/linebender/resvg (default: cloned into
#   /tmp/resvg-src). Its crates/resvg/tests is copied to OUT_DIR/tests (default
#   /tmp/resvg-suite), where the injected copies are written beside the originals (relative
#   links resolve against the file's folder); OUT_DIR/results.tsv has one line per file:
#   name, gradmesh's outcome, resvg's outcome, the exit status and message of a refusal.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
src=${1:-/tmp/resvg-src}
out=${2:-/tmp/resvg-suite}
if [ ! -d "$src/crates/resvg/tests/tests" ]; then
  git clone --depth 1 https://github.com/linebender/resvg "$src"
fi
rm -rf "$out/tests"
mkdir -p "$out"
cp -r "$src/crates/resvg/tests" "$out/tests"
cd "$root"
# The test profile (opt-level 2) builds the binary and the example; both run under nice.
nice cargo build --profile test --workspace --bin gradmesh --example resvg_suite
nice target/debug/examples/resvg_suite "$out/tests" target/debug/gradmesh "$out"
