"""The report of a model diagnosis: what ``sidbench diagnose`` found, where, and the proof.

``sidbench diagnose`` writes a folder ``DIR`` holding ``findings.json`` and the series tables
``series/identification.parquet`` (and ``series/validation.parquet`` when a validation
recording was given); the layout is the diagnosis data contract. This module reads that
folder and nothing else (it never flies, estimates or loads a model) and builds one
:class:`reports.render.Report` in five parts:

1. *Verdict*: the findings, most significant first, or a plain "nothing found" with its
   evidence.
2. *Where the mismatch is*: per channel and per axis mismatch against the noise, the time
   window and frequency band holding it, with figures.
3. *Candidates considered*: every candidate effect tested, by |t|, the selected highlighted.
4. *The chosen model*: the terms added and the augmented model's file.
5. *Before and after*: the fit of the model as given and of the augmented model on the
   identification maneuver and, when there is one, the validation maneuver.

Every optional piece (validation, located statistics, candidates, columns of the series) may
be missing: its table or figure is then left out, never guessed.
"""
from __future__ import annotations

import contextlib
import datetime as dt
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from harness.executors import LocalPool
from reports import figures_diagnosis as FD
from reports.figures_diagnosis import CHANNELS, COEFFICIENTS
from reports.render import KINDS, Report, Section, Table, format_number, format_value

__all__ = ["DiagnosisOutput", "read_diagnosis", "diagnosis_report", "write_diagnosis_report",
           "affected_channels", "affected_coefficients", "worst_channels"]

KIND = "diagnosis" if "diagnosis" in KINDS else "maneuver-review"
"""The report kind: ``'diagnosis'`` once :data:`reports.render.KINDS` lists it."""
MANEUVERS: tuple[str, ...] = ("identification", "validation")
AXIS_COEFFICIENT: Mapping[str, str] = {
    "pitch": "Cm", "roll": "Cl", "yaw": "Cn", "axial": "CX", "side": "CY", "normal": "CZ",
    "x": "CX", "y": "CY", "z": "CZ", "lift": "CZ", "drag": "CX", "sideforce": "CY"}
"""Axis words a finding may use, and the coefficient each names."""
COEFFICIENT_CHANNELS: Mapping[str, tuple[str, ...]] = {
    "Cm": ("q", "alpha", "theta", "az"), "CZ": ("alpha", "az", "q"), "CX": ("V", "ax"),
    "CY": ("beta", "ay"), "Cl": ("p", "phi"), "Cn": ("r", "beta")}
"""Output channels that show a coefficient's error first."""
SHOWN_CHANNELS = 3
IMPROVED = 0.10
"""Relative change of a fit metric counted as better (green) or worse (red)."""
HIGHER_IS_BETTER = ("lag_fraction_inside",)
FIT_GROUPS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("outputs", "output", ("rms", "theil_u")),
    ("coefficients", "coefficient residual", ("rms", "pse")),
    ("whiteness", "whiteness", ("lag_fraction_inside", "ljung_box_z")))


@dataclass(frozen=True)
class DiagnosisOutput:
    """One ``sidbench diagnose`` output folder.

    Attributes
    ----------
    path : Path
        The folder.
    data : dict
        ``findings.json``.
    series : dict of str to DataFrame
        The series tables present, by maneuver (``'identification'``, ``'validation'``).
    """

    path: Path
    data: dict
    series: dict[str, pd.DataFrame] = field(default_factory=dict)


def read_diagnosis(out_dir: str | Path) -> DiagnosisOutput:
    """Read ``findings.json`` and the series tables of a diagnosis folder.

    Parameters
    ----------
    out_dir : str or Path
        The folder ``sidbench diagnose`` wrote.

    Returns
    -------
    DiagnosisOutput

    Raises
    ------
    FileNotFoundError
        When ``findings.json`` is missing.
    """
    path = Path(out_dir)
    file = path / "findings.json"
    if not file.is_file():
        raise FileNotFoundError(f"{path} is not a diagnosis folder: findings.json missing "
                                "(run `sidbench diagnose` first)")
    data = json.loads(file.read_text())
    series = {m: pd.read_parquet(path / "series" / f"{m}.parquet") for m in MANEUVERS
              if (path / "series" / f"{m}.parquet").is_file()}
    return DiagnosisOutput(path, data if isinstance(data, dict) else {}, series)


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
# Which channels and axes to show
# --------------------------------------------------------------------------------------

def _coefficient_of(name: Any) -> str | None:
    """The coefficient an axis word or coefficient name refers to (``'pitch'`` -> ``'Cm'``)."""
    if not isinstance(name, str) or not name:
        return None
    if name in COEFFICIENTS:
        return name
    lower = name.lower()
    by_lower = {c.lower(): c for c in COEFFICIENTS}
    return by_lower.get(lower) or AXIS_COEFFICIENT.get(lower)


def _finding_coefficient(finding: Mapping) -> str | None:
    """The coefficient a finding acts on: its axis, else its parameter's prefix."""
    coef = _coefficient_of(finding.get("axis"))
    if coef is None and isinstance(finding.get("parameter"), str):
        coef = _coefficient_of(finding["parameter"].split("_")[0])
    return coef


def _ratios(located: Mapping, group: str, maneuver: str = "identification") -> dict[str, float]:
    """``located[group][maneuver][name]['ratio']`` (else ``'rms'``) per name."""
    table = _dict(_dict(_dict(located).get(group)).get(maneuver))
    out = {}
    for name, stats in table.items():
        stats = _dict(stats)
        value = _num(stats.get("ratio"))
        out[str(name)] = value if math.isfinite(value) else _num(stats.get("rms"))
    return out


def _series_ratios(series: pd.DataFrame | None) -> dict[str, float]:
    """Per channel, RMS of smoothed minus before over RMS of raw minus smoothed."""
    out: dict[str, float] = {}
    if series is None:
        return out
    for c in CHANNELS:
        cols = [f"meas_{c}", f"smooth_{c}", f"before_{c}"]
        if all(col in series for col in cols):
            meas, smooth, before = (pd.to_numeric(series[col], errors="coerce").to_numpy(float)
                                    for col in cols)
            noise = FD.rms(meas - smooth)
            out[c] = FD.rms(smooth - before) / noise if noise > 0 else FD.rms(smooth - before)
    return out


def _rank(scores: Mapping[str, float]) -> list[str]:
    """Names by descending score, NaN last."""
    return sorted(scores, key=lambda n: -scores[n] if math.isfinite(scores[n]) else math.inf)


def worst_channels(data: Mapping, series: pd.DataFrame | None, count: int = SHOWN_CHANNELS) -> list[str]:
    """The output channels that depart most from the model as given, worst first.

    Parameters
    ----------
    data : Mapping
        ``findings.json``.
    series : DataFrame or None
        The identification series (used when ``located`` holds no channel statistics).
    count : int, optional
        How many channels to return.

    Returns
    -------
    list of str
        From ``located.outputs.identification`` by noise ratio (``worst_output`` first), or
        computed from the series.
    """
    located = _dict(data.get("located"))
    ranked = _rank(_ratios(located, "outputs")) or _rank(_series_ratios(series))
    worst = located.get("worst_output")
    if isinstance(worst, str) and worst:
        ranked = [worst] + [c for c in ranked if c != worst]
    return ranked[:count]


def affected_channels(data: Mapping, series: pd.DataFrame | None) -> list[str]:
    """The output channels the findings name, else the worst ones.

    A finding's ``channel`` comes first; its axis adds the channels that show that axis's
    coefficient (``pitch`` -> q, alpha, theta, az), ordered by their mismatch.

    Parameters
    ----------
    data : Mapping
        ``findings.json``.
    series : DataFrame or None
        The identification series (for the fallback).

    Returns
    -------
    list of str
    """
    located = _dict(data.get("located"))
    ratios = _ratios(located, "outputs") or _series_ratios(series)
    named: list[str] = []
    for finding in _real(_findings(data)):
        if isinstance(finding.get("channel"), str) and finding["channel"]:
            named.append(finding["channel"])
        related = COEFFICIENT_CHANNELS.get(_finding_coefficient(finding) or "", ())
        named += sorted(related, key=lambda c: -ratios.get(c, -math.inf)
                        if math.isfinite(ratios.get(c, math.nan)) else math.inf)
    named = [c for c in dict.fromkeys(named) if c in CHANNELS]
    return named or worst_channels(data, series)


def affected_coefficients(data: Mapping) -> list[str]:
    """The coefficients the findings act on, else the worst axis (else every axis).

    Parameters
    ----------
    data : Mapping
        ``findings.json``.

    Returns
    -------
    list of str
    """
    named = [c for c in (_finding_coefficient(f) for f in _real(_findings(data))) if c]
    if named:
        return list(dict.fromkeys(named))
    located = _dict(data.get("located"))
    worst = _coefficient_of(located.get("worst_axis"))
    if worst:
        return [worst]
    return _rank(_ratios(located, "coefficients"))[:2] or list(COEFFICIENTS)


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
                 "explained_fraction is the share of the mismatch the candidate explains alone.",
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
                 "Outputs against the smoothed recording (RMS, Theil's U), the coefficient residual (RMS, "
                 "PSE) and its whiteness (share of autocorrelation lags inside the 95 % bounds, Ljung-Box "
                 f"z). Green: better after by {100 * IMPROVED:.0f} % or more; red: worse.", marks)


# --------------------------------------------------------------------------------------
# Sections
# --------------------------------------------------------------------------------------

def _figs(*items: Any) -> tuple:
    """The figures that could be drawn."""
    return tuple(f for f in items if f is not None)


def _finding_line(f: Mapping) -> str:
    """One summary line for a finding."""
    ev = _dict(f.get("evidence"))
    where = _where(f)
    stats = [f"t = {format_number(_num(ev.get('t')), 3)}"] if math.isfinite(_num(ev.get("t"))) else []
    share = _num(ev.get("explained_fraction"))
    if math.isfinite(share):
        stats.append(f"explains {100 * share:.0f} % of the mismatch")
    units = f" {f['units']}" if f.get("units") else ""
    head = f"{f.get('effect')}" + (f" ({where})" if where else "")
    body = f"{f.get('parameter')} = {_pm(f)}{units}" + (f" ({', '.join(stats)})" if stats else "")
    explanation = f" {f['explanation']}" if f.get("explanation") else ""
    return f"{head}: {body}.{explanation}"


def _none_line(findings: Sequence[Mapping]) -> str:
    """The plain sentence for a diagnosis that found nothing."""
    none = next((f for f in findings if f.get("effect") == "none"), {})
    why = f" {none['explanation']}" if none.get("explanation") else ""
    return "No effect found: the model as given explains the recording to within its noise." + why


def summary_lines(data: Mapping) -> list[str]:
    """The at-a-glance verdict: each finding (or 'nothing found') and where the mismatch is."""
    findings = _findings(data)
    real = _real(findings)
    lines = [_finding_line(f) for f in real] if real else [_none_line(findings)]
    summary = _dict(data.get("located")).get("summary")
    if isinstance(summary, str) and summary:
        lines.append(summary)
    return lines


def scope_section(data: Mapping) -> Section | None:
    """What the diagnosis assumed and what this recording could not test (findings.json's
    ``assumptions`` and ``not_checked``), shown right after the verdict."""
    assumed = [a for a in data.get("assumptions") or [] if isinstance(a, Mapping)]
    unchecked = [n for n in data.get("not_checked") or [] if isinstance(n, Mapping)]
    if not assumed and not unchecked:
        return None
    tables = []
    if assumed:
        tables.append(Table("Assumptions", pd.DataFrame(
            [{"what": a.get("item", ""), "missing": a.get("missing", ""), "assumed instead": a.get("stood_in_by", "")}
             for a in assumed]), "Where the recording is silent, what stood in. A finding may depend on these."))
    if unchecked:
        tables.append(Table("Not checked", pd.DataFrame(
            [{"effect": n.get("effect", ""), "parameters": ", ".join(map(str, n.get("parameters") or [])) or "—",
              "why": n.get("reason", "")} for n in unchecked]),
            "Effects (or their parameters) this recording cannot test: 'none' does not rule them out."))
    return Section("Assumptions and what was not checked",
                   ("The verdict holds under these assumptions and only for what the maneuver could show.",),
                   tuple(tables))


def verdict_section(data: Mapping) -> Section:
    """Section 1: the findings, or a plain 'nothing found' with its evidence."""
    findings = _findings(data)
    real = _real(findings)
    evidence = evidence_table(real or findings)
    unconfirmed = _unconfirmed_table(data)
    if not real:
        return Section("Verdict", (_none_line(findings),), _figs(evidence, unconfirmed))
    intro = (f"{len(real)} effect{'s' if len(real) > 1 else ''} found, most significant first. "
             "Each is a term the model as given lacks, estimated from the mismatch between the "
             "recording and the model.")
    return Section("Verdict", (intro,), _figs(findings_table(real), _calibration_table(data), evidence, unconfirmed))


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


def _located_lines(located: Mapping) -> tuple[str, ...]:
    """Plain sentences on where the mismatch is."""
    parts = [f"worst output channel {located['worst_output']}" if located.get("worst_output") else "",
             f"axis {located.get('focus_axis') or located['worst_axis']}" if located.get("worst_axis") else "",
             f"largest mismatch in {_span(located.get('time_window_s'), 's')}"
             if _span(located.get("time_window_s"), "s") else "",
             f"most of its power in {_span(located.get('band_hz'), 'Hz')}"
             if _span(located.get("band_hz"), "Hz") else ""]
    parts = [p for p in parts if p]
    lines = [located["summary"]] if isinstance(located.get("summary"), str) and located["summary"] else []
    if parts:
        lines.append("In short: " + "; ".join(parts) + ".")
    lines.append("ratio is the mismatch RMS over the noise standard deviation of the optimal smoother: "
                 "near 1 means the model is as good as the noise allows. structured_ratio counts only the part "
                 "of a coefficient mismatch that follows the maneuver's states and inputs (its least-squares fit on "
                 "them); noise in the measured states still leaves some there (the F-16's Cl shows 2-3 on a flight "
                 "with no model error).")
    return tuple(lines)


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


def located_section(data: Mapping, series: Mapping[str, pd.DataFrame]) -> Section:
    """Section 2: where the mismatch is, in channels, axes, time and frequency."""
    located = _dict(data.get("located"))
    ident = series.get("identification")
    window, band = located.get("time_window_s"), located.get("band_hz")
    worst_axis = _coefficient_of(located.get("worst_axis"))
    figures = _figs(FD.fig_worst_channels(ident, worst_channels(data, ident), "identification", window),
                    FD.fig_coefficient_mismatch(ident, worst_axis, window),
                    FD.fig_mismatch_spectrum(ident, worst_axis, band))
    return Section("Where the mismatch is", _located_lines(located), tuple(_located_tables(data)), figures)


def candidates_section(data: Mapping) -> Section:
    """Section 3: every candidate considered, by |t|."""
    candidates = [c for c in data.get("candidates") or [] if isinstance(c, Mapping)]
    if not candidates:
        return Section("Candidates considered", ("No candidate tests were recorded.",))
    chosen = sum(c.get("selected") is True for c in candidates)
    text = (f"{len(candidates)} candidate effects were tested on the mismatch; {chosen} "
            f"{'was' if chosen == 1 else 'were'} selected. The reason column says why each was or was not.")
    return Section("Candidates considered", (text,), (candidates_table(candidates),))


def _terms_table(terms: Any) -> Table | None:
    """The added terms as a table (records when they are mappings, else one column)."""
    if not isinstance(terms, list) or not terms:
        return None
    if all(isinstance(t, Mapping) for t in terms):
        frame = pd.DataFrame([{str(k): _scalar(v) for k, v in t.items()} for t in terms])
    else:
        frame = pd.DataFrame({"term": [format_value(t) for t in terms]})
    return Table("Added terms", frame, "The terms the augmented model adds to the model as given.")


def model_section(data: Mapping, out_dir: Path) -> Section:
    """Section 4: the chosen model, its added terms and where its file is."""
    model, inputs = _dict(data.get("model")), _dict(data.get("inputs"))
    lines = []
    base = model.get("base") or inputs.get("model")
    if base:
        lines.append(f"Base model: {base}.")
    xml = model.get("augmented_xml")
    if isinstance(xml, str) and xml:
        found = "" if (out_dir / xml).is_file() else " (not found in the folder)"
        lines.append(f"Augmented model: {xml}, relative to {out_dir}{found}.")
    table = _terms_table(model.get("terms"))
    if table is None:
        lines.append("No term was added: the augmented model is the model as given.")
    for maneuver in MANEUVERS:
        if inputs.get(maneuver):
            lines.append(f"{maneuver.capitalize()} recording: {inputs[maneuver]}.")
    return Section("The chosen model", tuple(lines), _figs(table))


def _fits(findings: Sequence[Mapping]) -> tuple[dict, dict]:
    """``fit_before`` and ``fit_after`` of the first finding carrying them (real ones first)."""
    for f in [*_real(findings), *findings]:
        before, after = _dict(f.get("fit_before")), _dict(f.get("fit_after"))
        if before or after:
            return before, after
    return {}, {}


def has_validation(data: Mapping, series: Mapping[str, pd.DataFrame]) -> bool:
    """Whether the folder holds a validation series or validation fits."""
    before, after = _fits(_findings(data))
    return "validation" in series or bool(_dict(before.get("validation")) or _dict(after.get("validation")))


def before_after_section(data: Mapping, series: Mapping[str, pd.DataFrame], maneuver: str) -> Section:
    """Section 5 (one per maneuver): the fit before and after the augmentation."""
    before, after = _fits(_findings(data))
    table = fit_table(maneuver, _dict(before.get(maneuver)), _dict(after.get(maneuver)))
    frame = series.get(maneuver)
    window = _dict(data.get("located")).get("time_window_s") if maneuver == "identification" else None
    figures = _figs(FD.fig_before_after_outputs(frame, affected_channels(data, series.get("identification")),
                                                maneuver, window),
                    FD.fig_before_after_coefs(frame, affected_coefficients(data), maneuver, window))
    lines = ("The maneuver the added terms were estimated from: a better fit here is expected, the "
             "validation maneuver is the test." if maneuver == "identification" else
             "A maneuver the estimate never saw: the augmented model must fit it better without refitting.",)
    failed = _dict(after.get(maneuver)).get("replay_failed")
    if failed:
        lines += (f"{failed}. The output fit after the change is therefore not shown; the coefficient fit is.",)
    if table is None and not figures:
        lines += ("No fit numbers or series were written for this maneuver.",)
    return Section(f"Before and after: {maneuver}", lines, _figs(table), figures)


def _before_after_sections(data: Mapping, series: Mapping[str, pd.DataFrame]) -> list[Section]:
    roles = ("identification", "validation") if has_validation(data, series) else ("identification",)
    return [before_after_section(data, series, role) for role in roles]


def diagnosis_sections(diag: DiagnosisOutput, workers: int = 2) -> list[Section]:
    """The report's sections, in order. With ``workers`` > 1 the before/after sections (half
    the figures) are drawn in a second process meanwhile."""
    data, series = diag.data, diag.series
    with contextlib.ExitStack() as stack:
        pending = None
        if workers > 1:
            pending = stack.enter_context(LocalPool(1)).pool.submit(_before_after_sections, data, series)
        scope = scope_section(data)
        sections = [verdict_section(data)] + ([scope] if scope is not None else []) + [
                    located_section(data, series), candidates_section(data), model_section(data, diag.path)]
        sections += pending.result() if pending is not None else _before_after_sections(data, series)
    return sections


# --------------------------------------------------------------------------------------
# The report
# --------------------------------------------------------------------------------------

def _provenance(diag: DiagnosisOutput) -> dict:
    """Where the numbers come from: the folder, its inputs, seed and run time."""
    data = diag.data
    inputs, model = _dict(data.get("inputs")), _dict(data.get("model"))
    total = _num(_dict(data.get("timing_s")).get("total"))
    return {"identification": inputs.get("identification"), "validation": inputs.get("validation"),
            "model": inputs.get("model") or model.get("base"), "seed": data.get("seed"),
            "folder": str(diag.path), "run_time": f"{total:.3g} s" if math.isfinite(total) else None,
            "generated_at": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")}


def _title(data: Mapping) -> str:
    """``'Diagnosis: f16 against ident.csv'`` (less when the inputs are not named)."""
    inputs, model = _dict(data.get("inputs")), _dict(data.get("model"))
    base = inputs.get("model") or model.get("base")
    ident = inputs.get("identification")
    title = f"Diagnosis: {base}" if base else "Model diagnosis"
    return title + (f" against {Path(str(ident)).name}" if ident else "")


def _numbers(diag: DiagnosisOutput) -> dict:
    """Everything ``findings.json`` holds, plus the shape of each series table."""
    shapes = {m: {"rows": int(len(s)), "columns": [str(c) for c in s.columns]} for m, s in diag.series.items()}
    return {"report": "diagnosis", **diag.data, "series": shapes}


def diagnosis_report(out_dir: Path, workers: int = 2) -> Report:
    """The report of a ``sidbench diagnose`` output folder.

    Parameters
    ----------
    out_dir : Path
        The folder holding ``findings.json`` and ``series/``.
    workers : int
        Above 1, the before/after figures are drawn in a second process (same report).

    Returns
    -------
    Report
        Sections: verdict, where the mismatch is, candidates considered, the chosen model,
        before and after (identification, and validation when present).
    """
    diag = read_diagnosis(out_dir)
    return Report(title=_title(diag.data), kind=KIND, provenance=_provenance(diag),
                  summary=tuple(summary_lines(diag.data)), sections=tuple(diagnosis_sections(diag, workers)),
                  numbers=_numbers(diag), status="findings" if _real(_findings(diag.data)) else "ok")


def write_diagnosis_report(out_dir: Path, workers: int = 2) -> Path:
    """Write ``report.html``, ``report.md`` and ``report.json`` into the diagnosis folder.

    Each file is written atomically (a temporary file renamed into place).

    Parameters
    ----------
    out_dir : Path
        The folder ``sidbench diagnose`` wrote.
    workers : int
        Processes drawing the figures (:func:`diagnosis_sections`).

    Returns
    -------
    Path
        The HTML report's path, ``out_dir / 'report.html'``.
    """
    from reports.commands import write_all  # here, so that commands may import this module
    return write_all(diagnosis_report(Path(out_dir), workers), Path(out_dir), "report")
