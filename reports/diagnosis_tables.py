"""The tables of the diagnosis report, and the small readers of ``findings.json`` they share.

This module owns the readers of the loosely typed JSON (``_dict``, ``_num``, ``_scalar``,
``_findings``, ``_real``, ``_pm``, ``_where``, ``_span`` ...) and every table the report
shows: the findings, their evidence, the candidates, the fit before and after, the mismatch
and noise tables, the sizes refined in the loop, the terms not confirmed and the added terms,
with their helpers (``_stats_frame``, ``_by_ratio``, ``_mark``, ``_fit_rows`` ...). Which
channels to show lives in :mod:`reports.diagnosis_channels`; the sections and the report in
:mod:`reports.diagnosis_report`.
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from reports.figures_diagnosis import CHANNELS, COEFFICIENTS
from reports.render import Table
from reports.render_values import format_number, format_value

__all__ = ["findings_table", "evidence_table", "candidates_table", "fit_table"]

MANEUVERS: tuple[str, ...] = ("identification", "validation")
IMPROVED = 0.10
"""Relative change of a fit metric counted as better (green) or worse (red)."""
HIGHER_IS_BETTER = ("lag_fraction_inside",)
FIT_GROUPS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("outputs", "output", ("rms", "theil_u")),
    ("coefficients", "coefficient residual", ("rms", "pse")),
    ("whiteness", "whiteness", ("lag_fraction_inside", "ljung_box_z")))


# --------------------------------------------------------------------------------------
# Small readers of the loosely typed JSON
# --------------------------------------------------------------------------------------

def _dict(value: Any) -> dict:
    """``value`` if it is a mapping, else an empty dict."""
    return dict(value) if isinstance(value, Mapping) else {}

def _num(value: Any) -> float:
    """``value`` as float, NaN when it is not a number."""
    if isinstance(value, bool):
        return float("nan")
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")

def _scalar(value: Any) -> Any:
    """A table cell: scalars as they are, anything nested as text."""
    if value is None or isinstance(value, (str, int, float, bool, np.number)):
        return value
    return format_value(value)

def _findings(data: Mapping) -> list[dict]:
    """Every finding, in file order (most significant first)."""
    items = data.get("findings")
    return [dict(f) for f in items if isinstance(f, Mapping)] if isinstance(items, list) else []

def _real(findings: Iterable[Mapping]) -> list[dict]:
    """The findings that name an effect (all but ``'none'``)."""
    return [dict(f) for f in findings if str(f.get("effect", "none")) != "none"]

def _ordered(names: Iterable[str], canonical: Sequence[str]) -> list[str]:
    """Names in the canonical order, then the others in their own order."""
    names = list(dict.fromkeys(names))
    return [n for n in canonical if n in names] + [n for n in names if n not in canonical]

def _pm(finding: Mapping) -> str:
    """``'-2.9 ± 0.2'`` (or just the estimate when it has no standard error)."""
    est, se = _num(finding.get("estimate")), _num(finding.get("std_error"))
    text = format_number(est)
    return f"{text} ± {format_number(se)}" if math.isfinite(se) else text

def _where(finding: Mapping) -> str:
    """The axis and channel a finding names, joined (``'pitch'``, ``'alpha'``, ``'pitch / q'``)."""
    parts = [str(finding[k]) for k in ("axis", "channel") if finding.get(k) not in (None, "")]
    return " / ".join(parts)

def _span(value: Any, unit: str) -> str:
    """``'3.2-5.1 s'`` from a two-number list, or ``''``."""
    if isinstance(value, (list, tuple)) and len(value) == 2:
        a, b = _num(value[0]), _num(value[1])
        if math.isfinite(a) and math.isfinite(b):
            return f"{a:g}-{b:g} {unit}"
    return ""


# --------------------------------------------------------------------------------------
# Tables
# --------------------------------------------------------------------------------------

def _stats_frame(table: Mapping, first: Sequence[str], index: str,
                 canonical: Sequence[str]) -> pd.DataFrame:
    """A frame of per-name statistics: one row per name, ``first`` columns leading."""
    names = _ordered((str(n) for n in table), canonical)
    keys = list(dict.fromkeys(k for n in names for k in _dict(table.get(n))))
    columns = [k for k in first if k in keys] + [k for k in keys if k not in first]
    rows = [[_scalar(_dict(table.get(n)).get(k)) for k in columns] for n in names]
    frame = pd.DataFrame(rows, columns=columns, index=pd.Index(names, name=index))
    return frame.infer_objects()

def _by_ratio(frame: pd.DataFrame) -> pd.DataFrame:
    """Rows by descending ``ratio`` when the frame has one."""
    if "ratio" not in frame or frame.empty:
        return frame
    return frame.sort_values("ratio", ascending=False, na_position="last", kind="stable",
                             key=lambda s: pd.to_numeric(s, errors="coerce"))

def _mark(frame: pd.DataFrame, name: Any, css: str = "bad") -> tuple[tuple[int, str, str], ...]:
    """Highlight the ``ratio`` (else first) cell of the row named ``name``."""
    if not isinstance(name, str) or name not in frame.index or frame.columns.empty:
        return ()
    column = "ratio" if "ratio" in frame else frame.columns[0]
    return ((int(list(frame.index).index(name)), column, css),)

def findings_table(findings: Sequence[Mapping]) -> Table:
    """The findings: effect, where, parameter, estimate ± standard error, units, explanation."""
    rows = [{"effect": str(f.get("effect", "")), "axis / channel": _where(f),
             "parameter": _scalar(f.get("parameter")), "estimate": _num(f.get("estimate")),
             "std_error": _num(f.get("std_error")), "t": _num(_dict(f.get("evidence")).get("t")),
             "units": _scalar(f.get("units")),
             "on validation": _dict(_dict(f.get("evidence")).get("validation")).get("status", "—"),
             "explanation": _scalar(f.get("explanation"))}
            for f in findings]
    return Table("Findings", pd.DataFrame(rows),
                 "Most significant first, one row per finding with its parameter; estimate and std_error are in "
                 "the units column. t is the selecting test's statistic: for a coefficient error, (estimate − the "
                 "model's value over the maneuver) / std_error; for other terms, estimate / std_error (a spectral "
                 "peak: −log10 p; turbulence: the gust-to-noise ratio). Where the in-the-loop calibration was kept, "
                 "estimate and std_error are its refined size (the one the augmented model flies with; the "
                 "equation-error size is in findings.json's equation_error) while t stays the equation-error "
                 "test's. 'on validation': what the term, at its estimated size, does "
                 "to the validation maneuver's coefficient mismatch (confirmed: drops by 1 % or more; "
                 "contradicted: grows, and the term is left out of the augmented model; untested: that maneuver "
                 "does not excite the term, which rests on the identification maneuver alone).")

def evidence_table(findings: Sequence[Mapping]) -> Table | None:
    """Every evidence key of every finding, one row each (None when there is none)."""
    rows = [{"effect": str(f.get("effect", "")), "evidence": str(k), "value": _scalar(v)}
            for f in findings for k, v in _dict(f.get("evidence")).items()]
    if not rows:
        return None
    return Table("Evidence", pd.DataFrame(rows), "What each finding rests on, as the diagnosis wrote it.")

def candidates_table(candidates: Sequence[Mapping]) -> Table:
    """Every candidate by descending |t|, the selected ones highlighted."""
    columns = ["effect", "axis", "channel", "parameter", "estimate", "std_error", "units", "t",
               "explained_fraction", "selected", "reason"]
    frame = pd.DataFrame([{c: _scalar(cand.get(c)) for c in columns} for cand in candidates],
                         columns=columns)
    for c in ("estimate", "std_error", "t", "explained_fraction"):
        frame[c] = pd.to_numeric(frame[c], errors="coerce").astype(float)
    frame["selected"] = [c.get("selected") is True for c in candidates]
    frame = frame.iloc[np.argsort(-np.nan_to_num(frame["t"].abs().to_numpy(), nan=-1.0),
                                  kind="stable")].reset_index(drop=True)
    marks = tuple((i, col, "good") for i in np.flatnonzero(frame["selected"].to_numpy())
                  for col in ("effect", "t", "selected"))
    return Table("Candidates", frame,
                 "Every candidate effect tested, by descending |t|. Green: selected into the model. "
                 "explained_fraction is the share of the mismatch the candidate explains alone (a structural "
                 "mode's: of what the common filter leaves of its channel; none for turbulence, which drives "
                 "the flight rather than adding a term).",
                 tuple((int(i), c, css) for i, c, css in marks))

def _fit_value(fit: Mapping, group: str, name: str, metric: str) -> float:
    """``fit[group][name][metric]`` as float (NaN when absent)."""
    return _num(_dict(_dict(_dict(fit).get(group)).get(name)).get(metric))

def _change_css(metric: str, before: float, after: float) -> str:
    """'good' or 'bad' when ``after`` is better or worse than ``before`` by ``IMPROVED``."""
    if not (math.isfinite(before) and math.isfinite(after)) or before == 0:
        return ""
    change = (after - before) / abs(before)
    if metric in HIGHER_IS_BETTER:
        change = -change
    return "good" if change <= -IMPROVED else "bad" if change >= IMPROVED else ""

def _fit_rows(before: Mapping, after: Mapping) -> list[tuple[str, str, str, float, float]]:
    """(group, name, metric, before, after) for every metric either fit reports."""
    rows = []
    for group, label, metrics in FIT_GROUPS:
        b, a = _dict(_dict(before).get(group)), _dict(_dict(after).get(group))
        canonical = CHANNELS if group == "outputs" else COEFFICIENTS
        for name in _ordered((str(n) for n in [*b, *a]), canonical):
            keys = [k for k in [*_dict(b.get(name)), *_dict(a.get(name))] if k not in metrics]
            for metric in [*metrics, *dict.fromkeys(keys)]:
                vb, va = _fit_value(before, group, name, metric), _fit_value(after, group, name, metric)
                if math.isfinite(vb) or math.isfinite(va):
                    rows.append((label, name, metric, vb, va))
    return rows

def fit_table(maneuver: str, before: Mapping, after: Mapping) -> Table | None:
    """Before against after for one maneuver (None when neither fit has numbers)."""
    rows = _fit_rows(before, after)
    if not rows:
        return None
    frame = pd.DataFrame(rows, columns=["quantity", "name", "metric", "before", "after"])
    frame["change_pct"] = [100 * (a - b) / abs(b) if math.isfinite(a) and math.isfinite(b) and b else math.nan
                           for b, a in zip(frame["before"], frame["after"])]
    marks = tuple((i, "after", css) for i, (_, _, m, b, a) in enumerate(rows)
                  if (css := _change_css(m, b, a)))
    return Table(f"Before and after, {maneuver}", frame,
                 "Outputs against the smoothed recording (RMS, Theil's U; a modelled structural mode's band "
                 "put back in the outputs it rings in, raw RMS against the record itself), the coefficient "
                 "residual (RMS, "
                 "PSE) and its whiteness (share of autocorrelation lags inside the 95 % bounds, Ljung-Box "
                 f"z). Green: better after by {100 * IMPROVED:.0f} % or more; red: worse.", marks)

def _calibration_table(data: Mapping) -> Table | None:
    """The last step, JSBSim in the loop (findings.json's ``calibration``): each term's
    equation-error size against its calibrated size, and whether the calibrated one was used
    (only when it fits the identification and the validation maneuver no worse)."""
    cal = _dict(data.get("calibration"))
    rows = [{"parameter": _scalar(q.get("name")), "equation error": _num(q.get("equation_error")),
             "calibrated": _num(q.get("calibrated")), "std_error": _num(q.get("std_error")),
             "units": _scalar(q.get("units"))}
            for q in cal.get("parameters") or [] if isinstance(q, Mapping)]
    if not rows:
        return None
    used = "used" if cal.get("used") else "not used: the equation-error sizes are kept"
    return Table("Sizes refined in the loop", pd.DataFrame(rows),
                 f"The named terms refined by output error over JSBSim flights of the augmented aircraft "
                 f"(sidbench calibrate); calibrated sizes {used}. {_scalar(cal.get('reason', ''))}")

def _unconfirmed_table(data: Mapping) -> Table | None:
    """Terms the identification maneuver called for that the validation maneuver did not
    confirm, or the calibration in the loop did not support (findings.json's
    ``not_confirmed``): reported, not findings, not modelled."""
    rows = [{"effect": str(f.get("effect", "")), "parameter": _scalar(f.get("parameter")),
             "estimate": _num(f.get("estimate")), "std_error": _num(f.get("std_error")),
             "units": _scalar(f.get("units")),
             "on validation": _dict(_dict(f.get("evidence")).get("validation")).get("status", "—"),
             "why": _scalar(_dict(_dict(f.get("evidence")).get("validation")).get("reason", ""))}
            for f in data.get("not_confirmed") or [] if isinstance(f, Mapping)]
    if not rows:
        return None
    return Table("Not confirmed", pd.DataFrame(rows),
                 "Terms the identification maneuver called for but the validation maneuver did not confirm "
                 "(neutral or contradicted), or could not tell from a rival that fits as well (ambiguous: a "
                 "collinear candidate of the same axis, see the reason), or that the calibration in the loop "
                 "sized at nothing (unsupported): not findings, and left out of the augmented model.")

def _located_tables(data: Mapping) -> list[Table]:
    """Per maneuver output and coefficient mismatch tables, then the noise table."""
    located = _dict(data.get("located"))
    tables = []
    specs = (("outputs", "Output mismatch", ("rms", "rms_raw", "theil_u", "noise_std", "ratio"),
              "channel", CHANNELS, "worst_output"),
             ("coefficients", "Coefficient mismatch", ("rms", "noise_std", "ratio", "pse"), "axis",
              COEFFICIENTS, "worst_axis"))
    for maneuver in MANEUVERS:
        for group, title, first, index, canonical, worst in specs:
            stats = _dict(_dict(located.get(group)).get(maneuver))
            if stats:
                frame = _by_ratio(_stats_frame(stats, first, index, canonical))
                marks = _mark(frame, located.get(worst)) if maneuver == "identification" else ()
                tables.append(Table(f"{title}, {maneuver}", frame,
                                    "Worst first (by ratio). Red: the worst one." if marks else
                                    "Worst first (by ratio).", marks))
    noise = _dict(data.get("noise"))
    if noise:
        tables.append(Table("Noise per channel", _stats_frame(noise, ("std", "cutoff_hz"), "channel", CHANNELS),
                            "Standard deviation and cut-off frequency of the optimal smoother per channel."))
    return tables

def _terms_table(terms: Any) -> Table | None:
    """The added terms as a table (records when they are mappings, else one column)."""
    if not isinstance(terms, list) or not terms:
        return None
    if all(isinstance(t, Mapping) for t in terms):
        frame = pd.DataFrame([{str(k): _scalar(v) for k, v in t.items()} for t in terms])
    else:
        frame = pd.DataFrame({"term": [format_value(t) for t in terms]})
    return Table("Added terms", frame, "The terms the augmented model adds to the model as given.")
