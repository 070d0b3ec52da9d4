"""The README's Python example runs as written, from the repository root."""

import os
import re

from conftest import ROOT


def test_readme_python_example_runs():
    readme = (ROOT / "README.md").read_text()
    section = readme.split("\n## Python\n", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(blocks) == 1, "the README's Python section has one Python example"
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        scope = {}
        exec(compile(blocks[0], "README.md", "exec"), scope)
    finally:
        os.chdir(here)
    assert scope["pixels"].shape[1] == 1024
