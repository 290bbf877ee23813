"""The layout is the architecture: data flows models + maneuvers -> estimators -> harness ->
reports, and no package imports from one to its right; estimators know nothing of JSBSim.

Above every package sits the command line, the composition root (``COMPOSITION_ROOT``): the
modules that wire the packages together into ``sidbench``'s subcommands and benchmarks. They may
import any package, ``reports`` included; nothing else imports them. Imports are real import
statements: a module path in a string (``importlib.import_module("reports.x")``, a
``"reports.x:func"`` reference) would dodge the rule and is refused outside the one plug-in point
(``PLUGIN_POINTS``: a campaign's ``[method_factories]``, code the user names in a campaign file)."""
from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ORDER = ["models", "maneuvers", "estimators", "harness", "reports"]
COMPOSITION_ROOT = {"harness/cli.py", "harness/__main__.py", "harness/commands.py", "harness/bench.py"}
PLUGIN_POINTS = {"harness/tasks.py"}  # _estimator: a campaign's [method_factories] "module:callable"
_ROOT_MODULES = {p[:-3].replace("/", ".") for p in COMPOSITION_ROOT}
_PROJECT_REF = re.compile(rf"^({'|'.join(ORDER)})(\.\w+)*(:\w+)?$")
_DYNAMIC = {"import_module", "__import__"}


def _imports(path: Path) -> set[str]:
    """Every module a file imports by statement (``from a import b`` also names ``a.b``)."""
    tree = ast.parse(path.read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.add(node.module)
            out |= {f"{node.module}.{a.name}" for a in node.names}
    return out


def dynamic_imports(source: str) -> list[str]:
    """What in ``source`` loads a project module by a string: ``import_module``/``__import__`` calls
    (with a project path, or with a path only known at run time) and ``"pkg.mod:func"`` strings."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
            if name in _DYNAMIC:
                arg = node.args[0] if node.args else None
                if not isinstance(arg, ast.Constant) or _PROJECT_REF.match(str(arg.value)):
                    found.append(f"line {node.lineno}: {name}({ast.unparse(arg) if arg else ''})")
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and ":" in node.value \
                and _PROJECT_REF.match(node.value):
            found.append(f"line {node.lineno}: {node.value!r}")
    return found


def _python_files(package: str):
    for path in sorted((ROOT / package).rglob("*.py")):
        yield path, path.relative_to(ROOT).as_posix()


@pytest.mark.parametrize("package", ORDER)
def test_no_package_imports_from_its_right(package):
    rank = ORDER.index(package)
    for path, rel in _python_files(package):
        if rel in COMPOSITION_ROOT:
            continue
        for mod in _imports(path):
            top = mod.split(".")[0]
            if top in ORDER:
                assert ORDER.index(top) <= rank, f"{rel} imports {mod}"


@pytest.mark.parametrize("package", ORDER)
def test_only_the_composition_root_imports_the_composition_root(package):
    for path, rel in _python_files(package):
        if rel in COMPOSITION_ROOT:
            continue
        wired = _imports(path) & _ROOT_MODULES
        assert not wired, f"{rel} imports the command line ({', '.join(sorted(wired))})"


@pytest.mark.parametrize("package", ORDER)
def test_no_module_loads_a_project_module_by_a_string(package):
    for path, rel in _python_files(package):
        if rel in PLUGIN_POINTS:
            continue
        found = dynamic_imports(path.read_text())
        assert not found, f"{rel} loads project modules by string (use an import statement): {found}"


def test_the_scanner_sees_a_planted_import_module():
    assert dynamic_imports('import importlib\nm = importlib.import_module("reports.campaign_report")\n')
    assert dynamic_imports('from importlib import import_module\nimport_module("reports.load").read_output\n')
    assert dynamic_imports('import importlib\nname = "reports.x"\nimportlib.import_module(name)\n')
    assert dynamic_imports('p.set_defaults(func="reports.commands:cmd_demo")\n')
    assert not dynamic_imports('import importlib\nimportlib.import_module("numpy")\n')
    assert not dynamic_imports('text = "ratio: reports are written to OUT"\nx = "a:b"\n')


def test_a_planted_import_module_in_harness_fails_the_architecture_test(tmp_path):
    """Must-show 4: a copy of the tree with ``importlib.import_module("reports....")`` planted in a
    harness module fails this file's tests; the tree as it is passes them."""
    copy = tmp_path / "tree"
    copy.mkdir()
    for package in ORDER:
        shutil.copytree(ROOT / package, copy / package, ignore=shutil.ignore_patterns("__pycache__", "*.parquet"))
    (copy / "tests").mkdir()
    shutil.copy(__file__, copy / "tests" / "test_architecture.py")
    victim = copy / "harness" / "scores.py"
    victim.write_text(victim.read_text() + '\n\ndef _report():\n    import importlib\n'
                      '    return importlib.import_module("reports.campaign_report")\n')
    run = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/test_architecture.py",
           "-k", "string"]
    planted = subprocess.run(run, cwd=copy, capture_output=True, text=True)
    assert planted.returncode == 1, planted.stdout
    assert "harness/scores.py loads project modules by string" in planted.stdout
    victim.write_text((ROOT / "harness" / "scores.py").read_text())
    clean = subprocess.run(run, cwd=copy, capture_output=True, text=True)
    assert clean.returncode == 0, clean.stdout


def test_estimators_do_not_load_jsbsim():
    mods = [f"estimators.{p.stem}" for p in (ROOT / "estimators").glob("*.py") if p.stem != "__init__"]
    code = "import sys\n" + "".join(f"import {m}\n" for m in mods) + "print('jsbsim' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_every_code_folder_is_a_package():
    for package in ORDER:
        assert (ROOT / package / "__init__.py").is_file()
