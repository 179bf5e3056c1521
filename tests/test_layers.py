"""The layers run one way: sgc_env (env, scenarios, the paper's math) <- baselines <- the CLI."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _imported_modules(path: Path) -> set[str]:
    """Every absolute module name a file imports, at any depth (lazy imports included)."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


def _modules(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


@pytest.mark.parametrize("path", _modules("sgc_env"), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_sgc_env_module_imports_baselines(path):
    upward = {m for m in _imported_modules(path) if m == "baselines" or m.startswith("baselines.")}
    assert not upward, f"{path.relative_to(ROOT)} imports {sorted(upward)}"


@pytest.mark.parametrize(
    "path",
    [p for p in _modules("baselines") if "cli" not in p.relative_to(ROOT / "baselines").parts],
    ids=lambda p: str(p.relative_to(ROOT)),
)
def test_only_the_command_layer_imports_the_command_layer(path):
    upward = {m for m in _imported_modules(path) if m.startswith("baselines.cli")}
    assert not upward, f"{path.relative_to(ROOT)} imports {sorted(upward)}"


def test_import_sgc_env_loads_no_baselines_no_planner_no_scipy():
    code = (
        "import sys, sgc_env, gymnasium as gym\n"
        "loaded = sorted(m for m in sys.modules if m.split('.')[0] in ('baselines', 'scipy')"
        " or m in ('sgc_env.paper.plan', 'sgc_env.paper.course', 'sgc_env.paper.frames'))\n"
        "print(','.join(loaded))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    ).stdout.strip()
    assert out == "", f"import sgc_env loaded: {out}"


def test_the_detector_sees_a_lazy_upward_import(tmp_path):
    module = tmp_path / "lazy.py"
    module.write_text("def f():\n    from baselines.expert import SGCExpert\n    return 1\n")
    assert "baselines.expert" in _imported_modules(module)


@pytest.mark.parametrize(
    "path", _modules("sgc_env") + _modules("baselines"), ids=lambda p: str(p.relative_to(ROOT))
)
def test_every_module_opens_with_a_docstring(path):
    doc = ast.get_docstring(ast.parse(path.read_text(), filename=str(path)))
    assert doc and doc.strip(), f"{path.relative_to(ROOT)} has no module docstring"
