"""Times gradmesh.render of the Tucan at 1024 pixels from Python, to compare with the Rust
criterion figure of the same render (`cargo bench -p gradmesh --bench render`, docs/performance.md).

    python crates/gradmesh-py/benches/render_tucan.py [--runs 50]

Prints the median and the quartiles in milliseconds, for a new array each time and for `out=`
(the same array drawn into again). Run it on a quiet machine (`uptime`).
"""

import argparse
import os
import pathlib
import statistics
import time
import warnings

import numpy as np

import gradmesh

ROOT = pathlib.Path(__file__).resolve().parents[3]
TUCAN = ROOT.parent / "shared" / "realdata" / "gradientmeshimproved-off" / "Tucan_Tucan_Layer{}.off"


def times(render, runs):
    render()  # warm up: first-touch of memory, thread pool
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        render()
        out.append((time.perf_counter() - start) * 1e3)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=50)
    args = parser.parse_args()
    warnings.simplefilter("ignore", gradmesh.MeshWarning)  # the artwork's out-of-gamut colours
    doc = gradmesh.Document([gradmesh.read(str(TUCAN).format(k)).layers[0] for k in (5, 4, 3, 2, 1, 0)])
    pixels = gradmesh.render(doc, width=1024)
    buffer = np.empty_like(pixels)
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} cores, {pixels.shape[1]}x{pixels.shape[0]} px")
    for name, render in [
        ("new array", lambda: gradmesh.render(doc, width=1024)),
        ("out=", lambda: gradmesh.render(doc, width=1024, out=buffer)),
    ]:
        t = sorted(times(render, args.runs))
        q = statistics.quantiles(t, n=4)
        print(f"{name:10} median {statistics.median(t):7.2f} ms  (quartiles {q[0]:.2f} - {q[2]:.2f})")


if __name__ == "__main__":
    main()
