"""The scenes shipped with the package (the repository's ``scenes/*.toml``,
installed as package data), so that :mod:`ivt.sim` runs them without a
checkout: ``ivt.sim.run(ivt.scenes.path("drive"))``.
"""

from pathlib import Path
from typing import List

_DIR = Path(__file__).resolve().parent / "_scenes"


def names() -> List[str]:
    """Names of the shipped scenes (file stems, sorted)."""
    return sorted(p.stem for p in _DIR.glob("*.toml"))


def path(name: str) -> Path:
    """Path of the shipped scene ``name`` (see :func:`names`).

    Raises ``ValueError`` naming the known scenes for an unknown name.
    """
    p = _DIR / f"{name}.toml"
    if "/" in name or "\\" in name or not p.is_file():
        raise ValueError(f"argument `name` = {name!r}: not a shipped scene; known: {names()}")
    return p


__all__ = ["names", "path"]
