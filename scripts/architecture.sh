#!/usr/bin/env bash
# Regenerates docs/modules-core.svg and docs/modules-render.svg, the module graphs of
# crates/gradmesh/src (an arrow A -> B: A imports from B), from ../shared/tools/layers.py's
# --dot output: the core with `formats::*` and `render::*` folded into `formats` and
# `render`, and the renderer's own modules, boxed by stage (the folders under render/).
# Needs graphviz (dot).
# Run from anywhere: scripts/architecture.sh
set -euo pipefail
cd "$(dirname "$0")/.."
all=$(mktemp)
python3 ../shared/tools/layers.py crates/gradmesh/src --max-fn 100000 --dot "$all" > /dev/null
python3 - "$all" <<'PY'
import re, sys
edges = re.findall(r'"([^"]+)" -> "([^"]+)";', open(sys.argv[1]).read())
def graph(name, pairs, clusters=None):
    lines = [f'digraph {name} {{', '  rankdir=BT;',
             '  node [shape=box, fontname="Helvetica", fontsize=11];']
    for stage, nodes in sorted((clusters or {}).items()):
        lines.append(f'  subgraph "cluster_{stage}" {{ label="{stage}/"; fontname="Helvetica";')
        lines += [f'    "{n}" [label="{n.split("::")[-1]}"];' for n in sorted(nodes)]
        lines.append('  }')
    lines += [f'  "{a}" -> "{b}";' for a, b in sorted(set(pairs)) if a != b]
    return '\n'.join(lines + ['}']) + '\n'
fold = lambda m: m.split('::')[0]
core = [(fold(a), fold(b)) for a, b in edges]
inner = lambda m: '::'.join(m.split('::')[1:])  # render::plan::measure -> plan::measure
render = [(inner(a), inner(b)) for a, b in edges
          if a.startswith('render::') and b.startswith('render::')]
stages = {}
for n in {n for pair in render for n in pair if '::' in n}:
    stages.setdefault(n.split('::')[0], set()).add(n)
open('docs/modules-core.dot', 'w').write(graph('core', core))
open('docs/modules-render.dot', 'w').write(graph('render', render, stages))
PY
dot -Tsvg docs/modules-core.dot -o docs/modules-core.svg
dot -Tsvg docs/modules-render.dot -o docs/modules-render.svg
rm -f "$all"
echo docs/modules-core.svg docs/modules-render.svg
