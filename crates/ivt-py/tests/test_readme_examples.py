"""The `### Examples` code blocks of crates/ivt-py/README.md run as written,
in order, in one namespace; their assertions are the checks (each states its
independent reference in the README text before it)."""

import pathlib
import re

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def test_readme_examples_run() -> None:
    text = README.read_text()
    section = text.split("### Examples", 1)[1].split("\n### ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 10, len(blocks)
    namespace: dict = {}  # type: ignore[type-arg]
    for block in blocks:
        exec(compile(block, str(README), "exec"), namespace)
