"""The layout is the architecture: data flows models + maneuvers -> estimators -> harness ->
reports, and no package imports from one to its right; estimators know nothing of JSBSim."""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ORDER = ["models", "maneuvers", "estimators", "harness", "reports"]


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.add(node.module.split(".")[0])
    return out


@pytest.mark.parametrize("package", ORDER)
def test_no_package_imports_from_its_right(package):
    rank = ORDER.index(package)
    for path in (ROOT / package).rglob("*.py"):
        for mod in _imports(path):
            if mod in ORDER:
                assert ORDER.index(mod) <= rank, f"{path.relative_to(ROOT)} imports {mod}"


def test_estimators_do_not_load_jsbsim():
    mods = [f"estimators.{p.stem}" for p in (ROOT / "estimators").glob("*.py") if p.stem != "__init__"]
    code = "import sys\n" + "".join(f"import {m}\n" for m in mods) + "print('jsbsim' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_every_code_folder_is_a_package():
    for package in ORDER:
        assert (ROOT / package / "__init__.py").is_file()
