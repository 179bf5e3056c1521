"""The project's normal paths print no warning: the README's Python example and the main
commands, each in a fresh interpreter with DeprecationWarning turned into an error (Gymnasium's
"out of date" notice is one), and nothing on stderr."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SGC = ("import sys; from baselines.cli.main import main; sys.argv[0] = 'sgc'; "
       "raise SystemExit(main())")


def _run(code: str, *args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONWARNINGS": "error::DeprecationWarning",
           "PYTHONPATH": str(ROOT)}  # fmt: skip
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          env=env, cwd=ROOT, timeout=600, check=False)  # fmt: skip


def _readme_example() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "README.md has no Python example"
    return blocks[0]


def test_the_readmes_python_example_prints_no_warning() -> None:
    done = _run(_readme_example())
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert "position_error" in done.stdout  # it flew to its goals


@pytest.mark.parametrize(
    "argv",
    [
        ["evaluate", "--env", "all", "--policy", "expert,minimum-jerk,dynamic-constraints",
         "--episodes", "1", "--no-plots", "--out", "{tmp}/evaluate"],
        ["rollout", "--env", "SGCRod-v1", "--policy", "expert", "--no-compare",
         "--out", "{tmp}/rollout"],
        ["demo", "--no-video", "--no-gltf", "--out", "{tmp}/demo"],
    ],
    ids=["evaluate-all", "rollout", "demo"],
)  # fmt: skip
def test_project_commands_print_no_warning(argv: list[str], tmp_path: Path) -> None:
    done = _run(SGC, *(a.format(tmp=tmp_path) for a in argv))
    assert done.returncode == 0, done.stderr
    assert "Warning" not in done.stderr and "WARN" not in done.stderr, done.stderr
