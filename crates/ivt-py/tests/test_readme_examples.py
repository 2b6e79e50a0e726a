"""The `## A minimal example` code block of crates/ivt-py/README.md runs as
written; its assertion is the check (the README names its independent
reference). The examples that stood here before move, with their assertions,
to the guide's model chapters (docs/guide/src/model/*.md), whose Python blocks
`test_guide.py` runs."""

import pathlib
import re

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def test_readme_example_runs() -> None:
    text = README.read_text()
    section = text.split("## A minimal example", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, len(blocks)
    namespace: dict = {}  # type: ignore[type-arg]
    exec(compile(blocks[0], str(README), "exec"), namespace)
