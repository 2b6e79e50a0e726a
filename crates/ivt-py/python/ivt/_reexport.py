"""The one way the public modules expose the native module's objects."""

from types import ModuleType
from typing import Any, Dict, Sequence


def reexport(namespace: Dict[str, Any], native: ModuleType, names: Sequence[str]) -> None:
    """Bind each of ``names`` in ``namespace`` (a module's ``globals()``) to
    the object of the same name in ``native`` (a submodule of ``ivt._ivt``)."""
    for name in names:
        namespace[name] = getattr(native, name)
