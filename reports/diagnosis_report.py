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

This module reads the folder, builds the sections and assembles the report; the tables and the
readers of the JSON are in :mod:`reports.diagnosis_tables`, the choice of channels and axes in
:mod:`reports.diagnosis_channels`.
"""
from __future__ import annotations

import contextlib
import datetime as dt
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from harness.executors import LocalPool
from reports import figures_diagnosis as FD
from reports.diagnosis_channels import _coefficient_of, affected_channels, affected_coefficients, worst_channels
from reports.diagnosis_tables import (MANEUVERS, _calibration_table, _dict, _findings, _located_tables, _num, _pm,
                                      _real, _span, _terms_table, _unconfirmed_table, _where, candidates_table,
                                      evidence_table, findings_table, fit_table)
from reports.render import KINDS, Report, Section, Table
from reports.render_values import format_number

__all__ = ["DiagnosisOutput", "read_diagnosis", "diagnosis_report", "write_diagnosis_report"]

KIND = "diagnosis" if "diagnosis" in KINDS else "maneuver-review"
"""The report kind: ``'diagnosis'`` once :data:`reports.render.KINDS` lists it."""


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
    return ("No effect found: the model as given explains the recording to within its noise." + why +
            " Effects smaller than the detection limits (section 'Assumptions and what was not checked') are not "
            "ruled out.")

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
    limits = [r for r in data.get("detection_limits") or [] if isinstance(r, Mapping)]
    if not assumed and not unchecked and not limits:
        return None
    tables = []
    if assumed:
        tables.append(Table("Assumptions", pd.DataFrame(
            [{"what": a.get("item", ""), "missing": a.get("missing", ""),
              "assumed instead": a.get("stood_in_by", "") + (f" (but {a['contradicted_by']})"
                                                             if a.get("contradicted_by") else "")}
             for a in assumed]), "Where the recording is silent, what stood in. A finding may depend on these."))
    if unchecked:
        tables.append(Table("Not checked", pd.DataFrame(
            [{"effect": n.get("effect", ""), "parameters": ", ".join(map(str, n.get("parameters") or [])) or "—",
              "why": n.get("reason", "")} for n in unchecked]),
            "Effects (or their parameters) this recording cannot test: 'none' does not rule them out."))
    if limits:
        tables.append(limits_table(limits))
    return Section("Assumptions and what was not checked",
                   ("The verdict holds under these assumptions and only for what the maneuver could show.",),
                   tuple(tables))

def limits_table(limits: list[Mapping]) -> Table:
    """findings.json's ``detection_limits`` as a table: per tested, unnamed parameter the
    smallest estimate (a coefficient error's change from the model) its entry tests name."""
    def pct(r: Mapping) -> str:
        rel = r.get("relative_to_model")
        return f"{100 * rel:.0f} %" if isinstance(rel, (int, float)) and math.isfinite(rel) else "—"
    rows = [{"parameter": r.get("parameter", ""), "units": r.get("units", ""),
             "smallest named": f"{r.get('limit', float('nan')):.3g}",
             "standard error": f"{r.get('std_error', float('nan')):.3g}",
             "of the model's value": pct(r), "set by": r.get("rule", ""),
             "estimated size": f"{r.get('estimate', float('nan')):.3g}",
             "withheld (estimate above the limit)": r.get("withheld", "")} for r in limits]
    return Table("Detection limits", pd.DataFrame(rows),
                 "Tested parameters not named, and the size their estimate (a coefficient's change from the "
                 "model) must reach to be named: the largest of the entry t times the standard error, the "
                 "practical share of the coefficient's excursion, the stepwise's gain and the smallest sensor "
                 "error or delay worth naming. An effect at the limit is estimated above it about half the time. "
                 "Other rules (rivals, the validation maneuver) may still withhold a larger effect: a 'none' "
                 "rules out only what lies above these.")


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
    outside = [m for m in model.get("outside_the_aircraft") or [] if isinstance(m, Mapping)]
    if table is None:
        lines.append("No term was added to the aircraft: the augmented aircraft is the model as given."
                     if outside else "No term was added: the augmented model is the model as given.")
    for m in outside:  # a structural mode, turbulence: sensor- and atmosphere-side models (model/sensors.json)
        lines.append(f"Modelled outside the aircraft, {m.get('effect', '?')}: {m.get('model', '')}.")
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
