#!/usr/bin/env bash
# Regenerates docs/modules-core.svg and docs/modules-render.svg, the module graphs of
# crates/gradmesh/src (an arrow A -> B: A imports from B), from ../shared/tools/layers.py's
# --dot output: the core with `formats::*` and `render::*` folded into `formats` and
# `render`, and the renderer's own modules. Needs graphviz (dot).
# Run from anywhere: scripts/architecture.sh
set -euo pipefail
cd "$(dirname "$0")/.."
all=$(mktemp)
python3 ../shared/tools/layers.py crates/gradmesh/src --max-fn 100000 --dot "$all" > /dev/null
python3 - "$all" <<'PY'
import re, sys
edges = re.findall(r'"([^"]+)" -> "([^"]+)";', open(sys.argv[1]).read())
def graph(name, pairs):
    lines = [f'digraph {name} {{', '  rankdir=BT;',
             '  node [shape=box, fontname="Helvetica", fontsize=11];']
    lines += [f'  "{a}" -> "{b}";' for a, b in sorted(set(pairs)) if a != b]
    return '\n'.join(lines + ['}']) + '\n'
fold = lambda m: m.split('::')[0]
core = [(fold(a), fold(b)) for a, b in edges]
render = [(a.split('::')[1], b.split('::')[1]) for a, b in edges
          if a.startswith('render::') and b.startswith('render::')]
open('docs/modules-core.dot', 'w').write(graph('core', core))
open('docs/modules-render.dot', 'w').write(graph('render', render))
PY
dot -Tsvg docs/modules-core.dot -o docs/modules-core.svg
dot -Tsvg docs/modules-render.dot -o docs/modules-render.svg
rm -f "$all"
echo docs/modules-core.svg docs/modules-render.svg
