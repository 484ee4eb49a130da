"""The README's Python blocks run as written (in order, in a scratch folder): in a forked child of this process
(bladecase already imported, no interpreter start; what importing does is tested by the README's commands, through
the installed executable, in tests/test_docs_run.py), or in a fresh interpreter once this process has meshed
(conftest's ``fork_is_safe()``; the file runs right after tests/test_docs_run.py, which meshes only in children)."""

import os
import re
import subprocess
import sys
from pathlib import Path

from conftest import fork_is_safe, run_forked_split

ROOT = Path(__file__).resolve().parents[1]


def python_blocks() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def test_readme_python_blocks_run(tmp_path):
    blocks = python_blocks()
    assert len(blocks) >= 3
    source = "\n\n".join(blocks)
    env = {"MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"}
    if fork_is_safe():
        code, stdout, stderr = run_forked_split(source, cwd=tmp_path, env=env, timeout=600)
    else:
        script = tmp_path / "readme.py"
        script.write_text(source, encoding="utf-8")
        res = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=dict(os.environ, **env),
                             capture_output=True, text=True, timeout=600)
        code, stdout, stderr = res.returncode, res.stdout, res.stderr
    assert code == 0, stderr[-3000:]
    assert "True" in stdout  # the first orbit is admissible
    assert (tmp_path / "fe.png").stat().st_size > 0 and (tmp_path / "blade.msh").stat().st_size > 0
