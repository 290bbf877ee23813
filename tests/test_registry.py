"""One registry for estimators: every method, single-maneuver, multiple-maneuver or stepwise, is
built by ``make_estimator`` and fitted by its ``fit``; its capabilities are declared with it, so
the harness keeps no lists of method names of its own."""
from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from estimators.methods import COMBINED_METHODS, METHODS, REGISTRY, make_estimator, method_info
from estimators.multiple import fit_concatenated, fit_frequency_combined, fit_sequential
from estimators.regressors import RegressionData
from estimators.stepwise import stepwise_regression
from models.errors import OptionError

ROOT = Path(__file__).resolve().parents[1]


def _data(seed: int, n: int = 1500) -> RegressionData:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.02
    X = np.column_stack([np.sin(0.9 * t + seed) + 0.2 * np.sin(3.1 * t), 0.01 * np.cos(0.7 * t),
                         np.sign(np.sin(0.5 * t + seed)) * 0.017, 0.01 * rng.standard_normal(n)])
    z = X[:, :3] @ np.array([-0.08, -5.9, -0.53]) + 0.002 + 1e-3 * rng.standard_normal(n)
    return RegressionData.from_arrays(z, X, ("alpha", "qhat", "de", "junk"), 0.02, dependent="Cm")


def test_the_method_lists_come_from_the_registry():
    assert METHODS == ("ee-time", "ee-smooth", "ee-freq", "oe", "oe-freq", "fe")
    assert COMBINED_METHODS == ("ee-concat", "ee-sequential", "ee-sequential-unequal", "ee-freq-combined")
    assert set(REGISTRY) == set(METHODS) | set(COMBINED_METHODS) | {"stepwise"}
    assert method_info("ee-freq").domain == "frequency" and not method_info("ee-freq").bias
    assert method_info("ee-smooth").errors[0] == "colored"
    assert method_info("oe").whole_model and method_info("oe").errors == ("cramer-rao",)
    assert method_info("ee-time").error_types(("conventional", "colored")) == ("conventional", "colored")
    assert method_info("ee-freq").error_types(("colored",)) == ("conventional",)
    with pytest.raises(OptionError, match="unknown method"):
        method_info("nope")


@pytest.mark.parametrize("name", COMBINED_METHODS)
def test_multiple_maneuver_methods_fit_through_the_one_fit(name):
    ds = [_data(1), _data(2)]
    fit = make_estimator(name).fit(ds)
    direct = {"ee-concat": lambda: fit_concatenated(ds), "ee-sequential": lambda: fit_sequential(ds),
              "ee-sequential-unequal": lambda: fit_sequential(ds, equal_variances=False),
              "ee-freq-combined": lambda: fit_frequency_combined(ds)}[name]()
    assert fit.names == direct.names
    np.testing.assert_array_equal(np.asarray(fit.params), np.asarray(direct.params))
    np.testing.assert_array_equal(fit.cov, direct.cov)


def test_colored_concatenation_through_the_registry():
    ds = [_data(3), _data(4)]
    fit = make_estimator("ee-concat", errors="colored", max_lag=20).fit(ds)
    np.testing.assert_array_equal(fit.cov, fit_concatenated(ds, errors="colored", max_lag=20).cov)


def test_stepwise_fits_through_the_one_fit():
    d = _data(5)
    fit = make_estimator("stepwise").fit(d)
    direct = stepwise_regression(None, d)
    assert fit.names == direct.fit.names and "Cm_junk" not in fit.names
    np.testing.assert_array_equal(np.asarray(fit.params), np.asarray(direct.fit.params))


def test_colored_errors_are_refused_where_not_declared():
    with pytest.raises(OptionError, match="--errors colored"):
        make_estimator("ee-freq", errors="colored")


def _method_lists(tree: ast.AST) -> list[str]:
    """Collections of method names the code dispatches on: ``x in ("oe", "fe")`` and module-level
    ``NAMES = ("ee-time", "ee-smooth")``."""
    def names_of(node) -> list[str]:
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            return [e.value for e in node.elts if isinstance(e, ast.Constant) and e.value in REGISTRY]
        return []
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare) and any(isinstance(o, (ast.In, ast.NotIn)) for o in node.ops):
            found += [f"line {node.lineno}: in {ast.unparse(c)}" for c in node.comparators if names_of(c)]
    for node in getattr(tree, "body", []):
        if isinstance(node, ast.Assign) and len(names_of(node.value)) >= 2:
            found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


def test_the_harness_keeps_no_lists_of_method_names():
    for path in sorted((ROOT / "harness").glob("*.py")):
        found = _method_lists(ast.parse(path.read_text()))
        assert not found, f"{path.relative_to(ROOT)}: {found} (declare it in estimators/registry.py)"


def test_the_method_list_scanner_sees_a_list():
    assert _method_lists(ast.parse('TIME_DOMAIN = ("ee-time", "ee-smooth")\n'))
    assert _method_lists(ast.parse('ok = method in ("oe", "oe-freq", "fe")\n'))
    assert not _method_lists(ast.parse('spec = dict(methods=("ee-freq", "oe"))\n'))
