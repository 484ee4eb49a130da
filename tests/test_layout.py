"""The shape of the package that docs/architecture.md promises: no import circles between its modules (counting
the imports inside functions), no module over 600 lines, and no downstream package imported by an upstream one
(``nsm`` imports no FE code, ``post`` no study)."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import bladecase

ROOT = Path(bladecase.__file__).parent

#: The most lines a module may have (docs/architecture.md).
MAX_LINES = 600


@functools.cache
def _imports(path: Path) -> tuple[ast.Import | ast.ImportFrom, ...]:
    """The import statements of ``path`` (anywhere in it), parsed once for the file's tests (each reads the same
    package: parsing it is most of their time)."""
    return tuple(node for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
                 if isinstance(node, ast.Import | ast.ImportFrom))


def _modules() -> dict[str, Path]:
    out = {}
    for path in ROOT.rglob("*.py"):
        parts = ("bladecase", *path.relative_to(ROOT).with_suffix("").parts)
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def _graph(mods: dict[str, Path]) -> dict[str, set[str]]:
    """Module → the project modules it imports (anywhere in it); an import of a package's own ``__init__`` by one
    of its modules is left out (the package is its parent, not a peer)."""
    edges: dict[str, set[str]] = {m: set() for m in mods}
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in _imports(path):
            targets = []
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    module = ".".join(base + ([node.module] if node.module else []))
                else:
                    module = node.module or ""
                targets = [module] + [f"{module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            edges[name] |= {t for t in targets if t in mods and t != name and not name.startswith(t + ".")}
    return edges


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in edges:
        if v not in index:
            visit(v)
    return out


@functools.cache
def _package_graph() -> dict[str, set[str]]:
    """:func:`_graph` of the package (read, not changed, by the tests)."""
    return _graph(_modules())


def test_no_import_circles():
    assert _cycles(_package_graph()) == []


def test_the_circle_finder_finds_a_circle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_module_is_over_600_lines():
    sizes = {name: len(path.read_text(encoding="utf-8").splitlines()) for name, path in _modules().items()}
    assert {n: s for n, s in sizes.items() if s > MAX_LINES} == {}


def test_imports_flow_downstream():
    """fe → reduction → nsm → post: ``nsm`` imports neither ``fe`` nor ``reduction`` nor ``study``; ``fe`` none of
    the packages after it."""
    edges = _package_graph()
    later = {"bladecase.fe": ("bladecase.reduction", "bladecase.nsm", "bladecase.study", "bladecase.cli"),
             "bladecase.nsm": ("bladecase.fe", "bladecase.reduction", "bladecase.post", "bladecase.study",
                               "bladecase.cli"),
             "bladecase.reduction": ("bladecase.study", "bladecase.cli"),
             "bladecase.post": ("bladecase.study", "bladecase.cli")}
    wrong = sorted((m, t) for m, ts in edges.items() for t in ts for pkg, bad in later.items()
                   if (m == pkg or m.startswith(pkg + ".")) and any(t == b or t.startswith(b + ".") for b in bad))
    # the one exception: Branch.plot(), a convenience that draws with bladecase.post.plots when it is called
    assert wrong == [("bladecase.nsm.branches", "bladecase.post.plots")]


def test_relative_imports_name_modules_that_exist():
    """Every ``from .x import …`` inside the package names a module or package of the package (an import inside a
    function is only run when that function is: a module moved without it would fail only there)."""
    mods = _modules()
    wrong = []
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in _imports(path):
            if isinstance(node, ast.ImportFrom) and node.level and node.module:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + [node.module])
                if target not in mods:
                    wrong.append((name, node.lineno, target))
    assert wrong == []
