"""The documentation runs as written, and speaks to users (README.md and every docs/*.md page).

What is run, and the rule for what is not
-----------------------------------------

* **Python** — every fenced ```python block of a docs/*.md page, the blocks of a page concatenated in order and
  run as one script (a fresh namespace per page, as ``__main__``) in a forked child of this process, where bladecase
  is already imported (no interpreter start; what importing does is tested by the commands below, through the
  installed executable) — or in a fresh interpreter: for a page that starts processes (:data:`STARTS_PROCESSES`:
  spawned workers import the page's script as ``__main__``, so its ``if __name__ == "__main__"`` guard matters),
  and for every page once this process has meshed (conftest's ``fork_is_safe()``);
  in a temporary working directory that holds a link ``meshes`` to the repository's reference meshes (pages name
  ``meshes/plate.inp`` as a user in the repository's root would).  README.md's Python blocks are run by
  tests/test_readme.py and not again here.
* **Commands** — in fenced ```sh, ```bash and ```console blocks, every line that starts with ``bladecase `` (in
  console blocks: ``$ bladecase ``; a line ending in ``\\`` continues on the next; ``;`` separates commands):

  1. every such command, on every page, is parsed by bladecase's own argument parser
     (:func:`bladecase.cli.build_parser`): an unknown command or option, a missing required argument or a bad
     value fails, whatever the block;
  2. the commands of runnable blocks are run through the installed ``bladecase`` executable, page by page in
     order, in one temporary working directory per page (so ``bladecase demo --print-study > demo.toml`` makes
     the file the next lines use), and must exit with status 0 within ``TIMEOUT`` seconds.

* **Not run** (still parsed, rule 1):

  - a block whose info string says ``no-run`` (```sh no-run, ```python no-run): what takes longer than about
    20 s (a full study run, ``make ...``, a benchmark) or needs what a test does not have (a Dask scheduler, a
    batch queue, a user's own mesh or study file);
  - a command with a placeholder: an upper-case metavariable (``STUDY.toml``, ``DIR``) or ``[optional]``
    brackets; and ``--help`` (the parse of rule 1 prints the help);
  - lines that do not start with ``bladecase `` (``make``, ``python benchmarks/...``, ``dask ...``): shown to the
    reader, not run; the benchmark and example scripts they name must exist and know the options given;
  - the pages of :data:`NOT_RUN`, which this test does not own, for the reason given there.

The other tests: every ```toml block with a ``[study]`` table outside docs/study.md (which tests/test_study_docs.py
checks) is a valid study; relative links resolve; every docs page is listed in docs/index.md; and no user page
holds an issue number, a dated note or a path inside the repository's code (:data:`HYGIENE`).
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from conftest import fork_is_safe, fork_script

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

#: Seconds a runnable command or a page's Python may take (the whole file stays under ~40 s on 2 cores).
TIMEOUT = 60

#: Pages whose blocks are parsed but not run, with the reason.  (Pages owned elsewhere: fence their blocks
#: ``no-run`` where they cannot run, and remove them from here.)
NOT_RUN = {
    "docs/study.md": "its worked sequence needs the page's plate study saved by hand as plate.toml, and its Python "
                     "block saves the reader's own matrices M, K, w",
}

#: Patterns that user documentation must not hold: ``(name, regex, applies to code too, pages exempt)``.
HYGIENE = [
    ("an issue number", r"\b[Ii]ssues? #?\d+", True, ()),
    ("an issue reference '#N'", r"(?<![\w&/#])#\d+\b", False, ()),
    ("a dated note", r"\b20\d\d-\d\d-\d\d\b", True, ()),
    ("a path to a module of the package", r"\bbladecase/[\w/.<>*-]*\.py\b", True, ("docs/architecture.md",)),
    ("a path into the test suite", r"(?<![\w/.-])tests/", True, ("docs/architecture.md",)),
    ("a file outside the repository", r"/work/|\.\./shared/|\bscratch/", True, ()),
    ("lab-notebook prose", r"\b(?:this|last|previous|next|second|third) (?:session|stop)\b", True, ()),
]

#: Python that starts processes (a Dask local cluster, a process pool, an executor other than the serial one): the
#: page runs in a fresh interpreter.  Matched in the code without its comments (:func:`starts_processes`): a comment
#: naming another executor starts nothing.
STARTS_PROCESSES = re.compile(r"\b(?:DaskExecutor|ProcessExecutor|LocalCluster|multiprocessing)\b|"
                              r"\bmake_executor\((?!\s*[\"']serial[\"']\s*\))|__main__")

FENCE = re.compile(r"^```([^\n`]*)\n(.*?)^```", re.S | re.M)
SHELLS = {"sh", "bash", "shell", "console"}
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9_]*(\.[a-z]+)?$")


def rel(page: Path) -> str:
    return page.relative_to(ROOT).as_posix()


def blocks(page: Path) -> list[tuple[str, bool, str]]:
    """``(language, runnable, body)`` of every fenced block of ``page``."""
    out = []
    for info, body in FENCE.findall(page.read_text(encoding="utf-8")):
        words = info.split()
        lang = words[0].lower() if words else ""
        out.append((lang, "no-run" not in words and rel(page) not in NOT_RUN, body))
    return out


def commands(lang: str, body: str) -> list[str]:
    """The ``bladecase ...`` commands of a shell block (continuations joined, ``;`` split)."""
    lines, joined = [], ""
    for line in body.splitlines():
        if lang == "console":
            if not line.startswith("$ "):
                continue
            line = line[2:]
        if line.rstrip().endswith("\\"):
            joined += line.rstrip()[:-1] + " "
            continue
        lines.append(joined + line)
        joined = ""
    out = []
    for line in lines:
        for part in line.split(";"):
            part = part.strip()
            if part.startswith("bladecase ") or part == "bladecase":
                out.append(part)
    return out


def argv_of(command: str) -> tuple[list[str], bool]:
    """The arguments after ``bladecase`` (comments and redirections dropped) and whether the command holds a
    placeholder, `--help` or nothing at all (then it is parsed only)."""
    tokens = shlex.split(command, comments=True)[1:]
    for stop in (">", ">>", "|", "&&", "2>"):
        if stop in tokens:
            tokens = tokens[:tokens.index(stop)]
    placeholder = any(t.startswith("[") or t.endswith("]") for t in tokens)
    tokens = [t.strip("[]") for t in tokens if t.strip("[]")]
    placeholder |= any(PLACEHOLDER.match(t) for t in tokens) or "--help" in tokens or not tokens
    return tokens, placeholder


def documented_commands() -> list[tuple[str, str, bool]]:
    """``(page, command, runnable)`` of every documented ``bladecase`` command."""
    out = []
    for page in PAGES:
        for lang, runnable, body in blocks(page):
            if lang in SHELLS:
                for cmd in commands(lang, body):
                    out.append((rel(page), cmd, runnable and not argv_of(cmd)[1]))
    return out


def starts_processes(source: str) -> bool:
    """The page's Python may start processes (:data:`STARTS_PROCESSES`, comments left out)."""
    return bool(STARTS_PROCESSES.search(re.sub(r"#[^\n]*", "", source)))


def python_source(page: Path) -> str:
    return "\n\n".join(body for lang, runnable, body in blocks(page) if lang == "python" and runnable)


# ----------------------------------------------------------------------------- running the pages


def _workdir(tmp: Path) -> Path:
    tmp.mkdir(parents=True, exist_ok=True)
    (tmp / "meshes").symlink_to(ROOT / "meshes", target_is_directory=True)
    return tmp


def _env() -> dict:
    bindir = str(Path(sys.executable).parent)
    return dict(os.environ, MPLBACKEND="Agg", OPENBLAS_NUM_THREADS="1", PYVISTA_OFF_SCREEN="true",
                PATH=bindir + os.pathsep + os.environ.get("PATH", ""))


def _run_python(page: str, source: str, tmp: Path) -> str | None:
    """Run ``source`` in a fresh interpreter in ``tmp``; the failure in words, or None."""
    script = tmp / "page.py"
    script.write_text(source, encoding="utf-8")
    try:
        res = subprocess.run([sys.executable, str(script)], cwd=tmp, env=_env(), capture_output=True, text=True,
                             timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return f"{page}: its Python blocks took more than {TIMEOUT} s"
    if res.returncode != 0:
        return f"{page}: its Python blocks fail (exit {res.returncode}):\n{res.stderr[-3000:]}"
    return None


class _ForkedPage:
    """A page's Python running in a forked child (conftest's :func:`fork_script`), started now: ``result()`` is
    its failure in words, or None, like the futures of the fresh interpreters (``TIMEOUT`` from its start)."""

    def __init__(self, page: str, source: str, tmp: Path):
        self.page, self.log, self.deadline = page, tmp / "output.txt", time.monotonic() + TIMEOUT
        self.child = fork_script(source, log=self.log, cwd=tmp, env=_env())

    def result(self) -> str | None:
        self.child.join(max(0.0, self.deadline - time.monotonic()))
        if self.child.is_alive():
            self.stop()
            return f"{self.page}: its Python blocks took more than {TIMEOUT} s"
        if self.child.exitcode != 0:
            return f"{self.page}: its Python blocks fail (exit {self.child.exitcode}):\n{self.log.read_text()[-3000:]}"
        return None

    def stop(self) -> None:
        if self.child.is_alive():
            self.child.kill()
        self.child.join()


def _run_commands(page: str, cmds: list[str], tmp: Path) -> str | None:
    """Run ``cmds`` in order in ``tmp`` through the installed executable; the first failure in words, or None."""
    if shutil.which("bladecase", path=_env()["PATH"]) is None:
        return "the bladecase executable is not installed next to this interpreter"
    for cmd in cmds:
        try:
            res = subprocess.run(cmd, shell=True, cwd=tmp, env=_env(), capture_output=True, text=True,
                                 timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            return f"{page}: `{cmd}` took more than {TIMEOUT} s (fence its block `no-run` if it is meant to be slow)"
        if res.returncode != 0:
            return f"{page}: `{cmd}` exits with {res.returncode}:\n{(res.stderr or res.stdout)[-3000:]}"
    return None


def _python_pages() -> list[str]:
    return [rel(p) for p in PAGES if p.name != "README.md" and python_source(p)]


def _command_pages() -> list[str]:
    return sorted({page for page, _, runnable in documented_commands() if runnable})


@pytest.fixture(scope="module")
def page_runs(tmp_path_factory):
    """Every page's Python and commands, started together (forked children, and two threads for the fresh
    processes; each job its own process and folder): ``{("python" | "commands", page): future of the failure in
    words or None}``.

    The pages forked (not :data:`STARTS_PROCESSES`, and only while conftest's ``fork_is_safe()``: a page may mesh)
    start first, from this thread before any other runs (a fork copies only the forking thread).  Then the command
    sequences: the README's is the longest job (its commands one after the other), and the Python pages in fresh
    interpreters run on the other thread meanwhile, so the file takes about as long as that one sequence."""
    by_page: dict[str, list[str]] = {}
    for page, cmd, runnable in documented_commands():
        if runnable:
            by_page.setdefault(page, []).append(cmd)
    jobs = {}
    fresh = []
    forkable = fork_is_safe()
    for page in _python_pages():
        source = python_source(ROOT / page)
        tmp = _workdir(tmp_path_factory.mktemp("python"))
        if starts_processes(source) or not forkable:
            fresh.append((page, source, tmp))
        else:
            jobs[("python", page)] = _ForkedPage(page, source, tmp)
    pool = ThreadPoolExecutor(max_workers=2)
    for page, cmds in sorted(by_page.items(), key=lambda item: -len(item[1])):
        tmp = _workdir(tmp_path_factory.mktemp("commands"))
        jobs[("commands", page)] = pool.submit(_run_commands, page, cmds, tmp)
    for page, source, tmp in fresh:
        jobs[("python", page)] = pool.submit(_run_python, page, source, tmp)
    yield jobs
    pool.shutdown(wait=True)
    for job in jobs.values():
        if isinstance(job, _ForkedPage):
            job.stop()


@pytest.mark.parametrize("page", _python_pages())
def test_python_blocks_run(page_runs, page):
    failure = page_runs[("python", page)].result()
    assert failure is None, failure


@pytest.mark.parametrize("page", _command_pages())
def test_commands_run(page_runs, page):
    failure = page_runs[("commands", page)].result()
    assert failure is None, failure


def test_every_documented_command_parses():
    from bladecase.cli import build_parser

    found = documented_commands()
    assert len(found) >= 10, "expected the README's and the docs' bladecase commands"
    for page, cmd, _ in found:
        argv, _ = argv_of(cmd)
        err = io.StringIO()
        try:
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
                build_parser().parse_args(argv)
        except SystemExit as exc:  # --help exits 0; a parse error exits 2
            assert exc.code == 0, f"{page}: `{cmd}` does not parse: {err.getvalue().strip()}"


# ----------------------------------------------------------------------------- consistency


def test_scripts_named_exist_with_their_options():
    """`benchmarks/...py` and `examples/...py` named in the docs exist and accept the options written after them."""
    pattern = re.compile(r"((?:benchmarks|examples)/[\w]+\.py)([^\n`|#;)]*)")
    for page in PAGES:
        for script, rest in pattern.findall(page.read_text(encoding="utf-8")):
            path = ROOT / script
            assert path.is_file(), f"{rel(page)} names {script}, which is not in the repository"
            helpers = sorted(path.parent.glob("_*.py"))  # e.g. the examples' shared argument parser
            source = "".join(f.read_text(encoding="utf-8") for f in [path, *helpers])
            for option in re.findall(r"(?<![\w-])(--[a-z][\w-]*)", rest.replace("\\", " ")):
                assert f'"{option}"' in source, f"{rel(page)}: {script} has no option {option}"


def test_study_examples_are_valid_studies():
    """TOML blocks with a [study] table (outside docs/study.md) load as studies."""
    from bladecase.study.schema import loads

    checked = 0
    for page in PAGES:
        if rel(page) == "docs/study.md":
            continue
        for lang, _, body in blocks(page):
            if lang == "toml" and re.search(r"^\[study\]", body, flags=re.M):
                tomllib.loads(body)
                loads(body, source=rel(page), base=ROOT)
                checked += 1
    assert checked >= 1, "expected the README's study example"


def test_links_resolve_and_index_lists_every_page():
    for page in PAGES + [ROOT / "CHANGELOG.md"]:
        fences = re.findall(r"^```", page.read_text(encoding="utf-8"), flags=re.M)
        assert len(fences) % 2 == 0, f"{rel(page)} has a code block that is never closed"
        text = FENCE.sub("", page.read_text(encoding="utf-8"))
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            path = (page.parent / target.split("#", 1)[0]).resolve()
            assert path.exists(), f"{rel(page)} links to {target}, which does not exist"
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    for page in sorted((ROOT / "docs").glob("*.md")):
        if page.name != "index.md":
            assert f"]({page.name})" in index, f"docs/index.md does not list {page.name}"
    assert "](docs/index.md)" in (ROOT / "README.md").read_text(encoding="utf-8"), "the README does not link the index"


def _prose(text: str) -> str:
    """``text`` without fenced blocks and inline code spans."""
    return re.sub(r"`[^`\n]*`", "", FENCE.sub("", text))


@pytest.mark.parametrize("page", [rel(p) for p in PAGES])
def test_user_docs_hold_no_lab_notes(page):
    text = (ROOT / page).read_text(encoding="utf-8")
    for name, pattern, in_code, exempt in HYGIENE:
        if page in exempt:
            continue
        hits = re.findall(pattern, text if in_code else _prose(text))
        assert not hits, f"{page} holds {name}: {hits[:5]} (history goes to CHANGELOG.md; name public API, not files)"
