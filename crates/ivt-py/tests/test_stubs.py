"""The `.pyi` stubs and the runtime agree: every public function and method
named in a stub has, at runtime, the same parameters in the same order, of
the same kind (positional, keyword-only, *args, **kwargs), with the same
defaults (`inspect.signature` against the stub's AST). A stub that drifts
from the Rust signature makes mypy accept calls that fail, or refuse calls
that work."""

import ast
import importlib
import inspect
import pathlib
from typing import Any, List, Optional, Tuple

import pytest

import ivt

PKG = pathlib.Path(ivt.__file__).parent
STUBS = sorted(p.stem for p in PKG.glob("*.pyi") if not p.stem.startswith("_"))

_KINDS = {
    "posonly": inspect.Parameter.POSITIONAL_ONLY,
    "args": inspect.Parameter.POSITIONAL_OR_KEYWORD,
    "vararg": inspect.Parameter.VAR_POSITIONAL,
    "kwonly": inspect.Parameter.KEYWORD_ONLY,
    "kwarg": inspect.Parameter.VAR_KEYWORD,
}

_NO_DEFAULT = object()


def _literal(d: Optional[ast.expr]) -> object:
    """A stub default: its value, Ellipsis when the stub elides it (`...`)
    or writes a non-literal expression, or _NO_DEFAULT."""
    if d is None:
        return _NO_DEFAULT
    try:
        return ast.literal_eval(d)
    except ValueError:
        return Ellipsis


def _stub_params(fn: ast.FunctionDef) -> List[Tuple[str, Any, object]]:
    """(name, kind, default) of a stub function, `self` dropped."""
    a = fn.args
    out: List[Tuple[str, Any, object]] = []
    positional = a.posonlyargs + a.args
    defaults: List[Optional[ast.expr]] = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    for i, (arg, d) in enumerate(zip(positional, defaults)):
        kind = _KINDS["posonly"] if i < len(a.posonlyargs) else _KINDS["args"]
        out.append((arg.arg, kind, _literal(d)))
    if a.vararg:
        out.append((a.vararg.arg, _KINDS["vararg"], _NO_DEFAULT))
    for arg, d in zip(a.kwonlyargs, a.kw_defaults):
        out.append((arg.arg, _KINDS["kwonly"], _literal(d)))
    if a.kwarg:
        out.append((a.kwarg.arg, _KINDS["kwarg"], _NO_DEFAULT))
    if out and out[0][0] in ("self", "cls"):
        out = out[1:]
    return out


def _decorated(fn: ast.FunctionDef, name: str) -> bool:
    return any(isinstance(d, ast.Name) and d.id == name for d in fn.decorator_list)


def _stub_functions(module: str) -> List[Tuple[str, ast.FunctionDef]]:
    """Qualified name and AST of every public def, module level and methods
    (each `@overload` variant separately; properties are attributes)."""
    tree = ast.parse((PKG / f"{module}.pyi").read_text())
    out: List[Tuple[str, ast.FunctionDef]] = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            out.append((node.name, node))
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                public = not item.name.startswith("_") if isinstance(item, ast.FunctionDef) else False
                if isinstance(item, ast.FunctionDef) and (public or item.name == "__init__"):
                    if not _decorated(item, "property"):
                        out.append((f"{node.name}.{item.name}", item))
    return out


def _runtime(module: str, qualname: str) -> Any:
    obj: Any = importlib.import_module(f"ivt.{module}")
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


def _runtime_params(obj: Any, is_method: bool) -> List[Tuple[str, Any, object]]:
    """(name, kind, default) of the runtime signature, `self` dropped (a pyo3
    method looked up on its class shows it as positional-only `self`)."""
    params = list(inspect.signature(obj).parameters.values())
    if is_method and params and params[0].name in ("self", "$self", "cls"):
        params = params[1:]
    return [
        (p.name, p.kind, _NO_DEFAULT if p.default is inspect.Parameter.empty else p.default)
        for p in params
    ]


CASES = [
    (module, qualname, i)
    for module in STUBS
    for i, (qualname, _) in enumerate(_stub_functions(module))
]


def test_every_stub_is_checked() -> None:
    """The parametrized check below covers every stub module's public API."""
    assert set(STUBS) >= {"ctrl", "design", "hb", "kin", "sim"}
    assert len(CASES) >= 40, len(CASES)


@pytest.mark.parametrize("module,qualname,index", CASES)
def test_stub_signature_matches_runtime(module: str, qualname: str, index: int) -> None:
    """Each stub def (every @overload variant too) against the runtime object."""
    fn = _stub_functions(module)[index][1]
    is_init = qualname.endswith(".__init__")
    obj = _runtime(module, qualname[: -len(".__init__")] if is_init else qualname)
    want = _stub_params(fn)
    got = _runtime_params(obj, "." in qualname)
    assert [(n, k) for n, k, _ in got] == [(n, k) for n, k, _ in want], qualname
    for (name, _, d_got), (_, _, d_want) in zip(got, want):
        if d_want is _NO_DEFAULT:
            assert d_got is _NO_DEFAULT, f"{qualname}({name}): runtime has a default, stub none"
        else:
            assert d_got is not _NO_DEFAULT, f"{qualname}({name}): stub has a default, runtime none"
            if Ellipsis not in (d_got, d_want):  # pyo3 shows a default it cannot render as `...`
                assert d_got == d_want, f"{qualname}({name}): runtime {d_got!r} vs stub {d_want!r}"
