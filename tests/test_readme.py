"""The README's environment example runs as printed."""

from __future__ import annotations

import re
from pathlib import Path


def test_readme_environment_example_runs():
    text = (Path(__file__).parent.parent / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "README has no python example"
    namespace: dict = {}
    exec(compile(blocks[0], "README.md", "exec"), namespace)  # noqa: S102
    assert namespace["truncated"] or namespace["terminated"]
    assert namespace["obs"].shape == (19,)
