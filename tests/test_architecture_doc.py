"""docs/architecture.md stays short and true: under 1,500 words, every path and dotted ``bladecase.x.y`` name it
gives exists, its extension table keeps its rows (one line each), and the rules it states are those that
tests/test_layout.py checks."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"

#: The most words the page may have (``wc -w``: every whitespace-separated token, table pipes included).
MAX_WORDS = 1500

#: Folders of the repository (not of the package) a path in the page may start with.
REPO_FOLDERS = ("docs", "tests", "benchmarks", "examples", "meshes")

#: The kinds of extension the table must keep, each the start of one row's first cell (bold removed).
EXTENSIONS = ("a mesh format", "an element", "a geometry kind", "a reduction method", "a contact law",
              "a casing property", "friction, wear, rub", "an analysis", "a study kind", "a study key",
              "an output format", "a plot", "a verdict reason", "a comparison measure", "a continuation problem",
              "a factorisation backend", "an executor")

#: The most words one row of the extension table may have.
MAX_ROW_WORDS = 40

SPAN = re.compile(r"`([^`\n]+)`")
PATH = re.compile(r"^[\w.*<>/-]+$")
DOTTED = re.compile(r"\bbladecase(?:\.\w+)+")


def text() -> str:
    return DOC.read_text(encoding="utf-8")


def paths(doc: str) -> list[str]:
    """The file and folder paths of ``doc``'s inline code spans: a span of path characters with a ``/`` in it
    or ending in ``.py``."""
    return [s for s in SPAN.findall(doc) if PATH.match(s) and ("/" in s or s.endswith(".py"))]


def missing_paths(doc: str) -> list[str]:
    """The paths of ``doc`` that match nothing: relative to the package folder ``bladecase/`` (a leading
    ``bladecase/`` allowed), or to the repository for :data:`REPO_FOLDERS`; ``<kind>`` and ``*`` are wildcards
    that must match at least one entry; a trailing ``/`` asks for a folder."""
    out = []
    for path in paths(doc):
        pattern = re.sub(r"<[^>]*>", "*", path.removeprefix("bladecase/")).rstrip("/")
        base = ROOT if pattern.split("/")[0] in REPO_FOLDERS else ROOT / "bladecase"
        found = base.glob(pattern) if pattern else [base]
        hits = [p for p in found if p.is_dir() or not path.endswith("/")]
        if not hits:
            out.append(path)
    return out


def _defined(body: list[ast.stmt]) -> dict[str, ast.stmt]:
    """The names a module or class body binds at its top level (definitions, assignments, imports)."""
    out: dict[str, ast.stmt] = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            out[node.name] = node
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                out.update({n.id: node for n in ast.walk(target) if isinstance(n, ast.Name)})
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            out.update({(a.asname or a.name).split(".")[0]: node for a in node.names})
    return out


def resolves(name: str) -> bool:
    """Whether the dotted ``name`` is a module of the package, a name its source binds at top level, or a member
    of a class defined there (``bladecase.a.b.C.meth``) — read from the source, nothing imported."""
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        folder = ROOT.joinpath(*parts[:cut])
        source = folder / "__init__.py" if folder.is_dir() else folder.with_suffix(".py")
        if source.is_file():
            break
    else:
        return False
    body = ast.parse(source.read_text(encoding="utf-8")).body
    for attr in parts[cut:]:
        node = _defined(body).get(attr)
        if node is None:
            return False
        body = node.body if isinstance(node, ast.ClassDef) else []
    return True


def table_rows(doc: str) -> list[str]:
    """The body rows of the 'Where each kind of extension goes' table."""
    section = doc.split("## Where each kind of extension goes", 1)[1]
    rows = [line for line in section.splitlines() if line.startswith("|")]
    return rows[2:]


def test_the_page_is_under_1500_words():
    words = len(text().split())
    assert words < MAX_WORDS, f"docs/architecture.md has {words} words (at most {MAX_WORDS - 1}): move details into " \
                              "the packages' __init__ docstrings"


def test_every_path_it_names_exists():
    assert len(paths(text())) >= 50, "expected the page to name the packages' main modules"
    assert missing_paths(text()) == []


def test_every_dotted_name_resolves():
    names = sorted(set(DOTTED.findall(text())))
    assert len(names) >= 8
    assert [n for n in names if not resolves(n)] == []


def test_the_checks_catch_a_wrong_name():
    doc = "`fe/mesh.py`, `fe/no_such_module.py`, `study/<kind>/stage.py`, `post/<kind>/missing.py`, `nsm/system.py/`"
    assert missing_paths(doc) == ["fe/no_such_module.py", "post/<kind>/missing.py", "nsm/system.py/"]
    assert resolves("bladecase.nsm.system.LinearSystem") and resolves("bladecase.study.run")
    assert resolves("bladecase.nsm.branches.Branch.compact") and not resolves("bladecase.nsm.branches.Branch.nope")
    assert not resolves("bladecase.nsm.system.NoSuchType") and not resolves("bladecase.no_such_package")


def test_the_extension_table_keeps_its_rows_one_line_each():
    rows = table_rows(text())
    firsts = [row.split("|")[1].replace("*", "").strip() for row in rows]
    for kind in EXTENSIONS:
        assert any(f.startswith(kind) for f in firsts), f"the extension table lost its row '{kind}'"
    long = {f: len(r.split()) for f, r in zip(firsts, rows) if len(r.split()) > MAX_ROW_WORDS}
    assert long == {}, f"rows over {MAX_ROW_WORDS} words: say the rest in the module's docstring"
    assert all(row.count("|") == 3 for row in rows), "each row is two cells on one line"


@pytest.mark.parametrize("package", ["fe", "reduction", "nsm", "post", "study", "cli"])
def test_each_package_has_its_paragraph(package):
    assert re.search(rf"^\*\*`{package}`\*\* — ", text(), flags=re.M), f"no paragraph for {package}"


def test_the_rules_are_those_the_layout_test_checks():
    from test_layout import MAX_LINES, test_imports_flow_downstream

    doc = text()
    assert f"No module over {MAX_LINES} lines" in doc
    source = Path(test_imports_flow_downstream.__code__.co_filename).read_text(encoding="utf-8")
    assert '[("bladecase.nsm.branches", "bladecase.post.plots")]' in source  # the one exception the page names
    assert "`Branch.plot()` (`nsm/branches.py` → `post/plots.py`)" in doc
    for rule in ("No import circles", "Imports flow downstream", "Every relative import"):
        assert rule in doc
