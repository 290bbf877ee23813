"""The lead of a campaign report: what the campaign is, what it flew, and what it found,
largest first, in sentences and small tables (the rules are in :mod:`reports.findings`)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from harness.campaign import NoiseDef
from reports.campaign_setup import Setup, flown_text, noise_table
from reports.figures_common import KNOWN_METHODS
from reports.findings import COVERAGE_BAND, Findings, method_label, rough_note
from reports.load import CampaignOutput
from reports.render import Section, Table

__all__ = ["MAX_CASE_LINES", "MAX_COVERAGE_GROUPS", "lead_lines", "status_note", "findings_section",
           "setup_section", "few_realizations_note"]

MAX_CASE_LINES: int = 6
"""Cases compared in the lead's sentences (the comparison table holds them all)."""
MAX_COVERAGE_GROUPS: int = 4
"""Methods named in the lead's coverage sentence."""
MAX_TABLE_ROWS: int = 15
"""Rows of the largest-bias and coverage-failure tables."""
_WHERE = {"regressors": "on the regressors", "outputs": "on the outputs", "both": "on every channel"}


def _z(value: float) -> str:
    """|bias| in Monte Carlo standard errors, to a sensible precision."""
    z = abs(float(value))
    return f"{z:.0f}" if z >= 100 else f"{z:.1f}"


def _pct(value: float) -> str:
    return f"{float(value):+.3g} %" if np.isfinite(value) else "— %"


def case_name(row: pd.Series, cases: tuple[str, ...]) -> str:
    """``'noise regressors'`` or ``'maneuver doublet, noise white'``."""
    return ", ".join(f"{c} {row[c]}" for c in cases) or "the campaign"


def noise_short(noise: NoiseDef | None) -> str:
    """A few words on a noise definition: ``'white sensor noise × 3 on the regressors'``."""
    if noise is None:
        return ""
    if noise.preset == "none":
        text = "clean regressors"
    else:
        scale = f" × {noise.scale:g}" if noise.scale != 1.0 else ""
        text = f"{noise.preset} sensor noise{scale} {_WHERE.get(noise.apply_to, noise.apply_to)}"
    if noise.output:
        text += ", output σ " + ", ".join(f"{k} {v:g}" for k, v in noise.output)
    return text


def _case_label(row: pd.Series, cases: tuple[str, ...]) -> str:
    name = case_name(row, cases)
    return f"{name[0].upper()}{name[1:]}"


def _case_definition(row: pd.Series, cases: tuple[str, ...], noises: dict[str, NoiseDef]) -> str:
    """`` (White sensor noise on the regressors, output σ Cm 0.0005.)`` or ''."""
    short = noise_short(noises.get(str(row.get("noise")))) if "noise" in cases else ""
    return f" ({short[0].upper()}{short[1:]}.)" if short else ""


def _method_z(row: pd.Series, with_parameter: bool) -> str:
    text = f"{method_label(row['method'])} {_z(row['bias_z'])}"
    return text + (f" ({row['parameter']} {_pct(row['bias_pct'])} of the truth)" if with_parameter else "")


def _biased(rows: pd.DataFrame) -> list[str]:
    """``['least squares (ee-time) is biased by 27.3 standard errors (Cm_de +1.68 % of the truth)',
    'frequency domain (ee-freq) by 6.0 (...)']``."""
    out = []
    for i, (_, r) in enumerate(rows.iterrows()):
        verb, unit = ("is biased by", " standard errors") if i == 0 else ("by", "")
        out.append(f"{method_label(r['method'])} {verb} {_z(r['bias_z'])}{unit} "
                   f"({r['parameter']} {_pct(r['bias_pct'])} of the truth)")
    return out


def _join(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def case_line(rows: pd.DataFrame, cases: tuple[str, ...], limit: float, noises: dict[str, NoiseDef]) -> str:
    """One case: which methods are biased beyond the limit (with their worst parameter), which
    not, then what the case's noise is."""
    label = _case_label(rows.iloc[0], cases)
    definition = _case_definition(rows.iloc[0], cases, noises)
    beyond = rows["abs_bias_z"] > limit
    fine = [_method_z(r, False) for _, r in rows[~beyond].iterrows()]
    if not beyond.any():
        return f"{label}: no method biased beyond {limit:.2f} standard errors ({_join(fine)}).{definition}"
    text = f"{label}: {_join(_biased(rows[beyond]))}"
    if not fine:
        return text + f", all beyond {limit:.2f}.{definition}"
    return text + f"; {_join(fine)} {'stays' if len(fine) == 1 else 'stay'} within {limit:.2f}.{definition}"


def _verdict(f: Findings) -> str:
    lo, hi = COVERAGE_BAND
    if not f.count:
        return (f"No finding: all {len(f.tests)} biases within {f.bias_limit:.2f} Monte Carlo standard errors and "
                f"every coverage consistent with [{lo:.2f}, {hi:.2f}].")
    return (f"Findings: {len(f.biases)} of {len(f.tests)} biases beyond {f.bias_limit:.2f} Monte Carlo standard "
            f"errors (Bonferroni, 1 % chance of any false alarm); coverage outside [{lo:.2f}, {hi:.2f}] in "
            f"{len(f.coverage)} of {f.cells_with_coverage} cells.")


def _largest(f: Findings) -> str:
    if f.tests.empty:
        return ""
    r = f.tests.iloc[0]
    what = "Largest bias" if r["abs_bias_z"] > f.bias_limit else "Largest bias (within the limit)"
    return (f"{what}: {method_label(r['method'])}, {case_name(r, f.cases)}: {r['parameter']} "
            f"{_pct(r['bias_pct'])} of the truth, {_z(r['bias_z'])} Monte Carlo standard errors.")


def _coverage_line(f: Findings) -> str:
    if f.coverage.empty:
        return ""
    c = f.coverage
    groups = c.groupby(["method", "errors"], sort=False)["coverage"].agg(["count", "min", "max"])
    groups = groups.sort_values("count", ascending=False, kind="stable")
    parts = [f"{m} ({e}) {int(g['count'])} cells, {g['min']:.2f}–{g['max']:.2f}"
             for (m, e), g in groups.head(MAX_COVERAGE_GROUPS).iterrows()]
    more = f" and {len(groups) - MAX_COVERAGE_GROUPS} more methods" if len(groups) > MAX_COVERAGE_GROUPS else ""
    lo, hi = COVERAGE_BAND
    return ("Coverage failures: " + "; ".join(parts) + more
            + f" (±2σ bounds whose 95 % coverage interval lies wholly outside [{lo:.2f}, {hi:.2f}]).")


def few_realizations_note(f: Findings) -> str:
    """The caveat for fewer than :data:`reports.findings.MIN_REALIZATIONS` realizations, or ''."""
    return rough_note(f.min_n)


def _run_line(out: CampaignOutput) -> str:
    m = out.meta
    c = m["campaign"]
    return (f"Run: {c.get('cells', '?')} cells × {c.get('realizations', '?')} realizations, "
            f"{m.get('estimates', len(out.results))} estimates in {m.get('wall_s', float('nan')):.1f} s on "
            f"{m.get('executor')}.")


def lead_lines(out: CampaignOutput, f: Findings, setup: Setup) -> list[str]:
    """The report's first lines: description, what was flown, the verdict, the largest bias,
    the comparison per case (worst first), coverage failures, caveats, the run."""
    c = out.meta["campaign"]
    noises = {n.name: n for n in setup.noises}
    lines = [f"{c['name']}: {c['description']}" if c.get("description") else str(c["name"]),
             flown_text(out.truth_scores) + f" {c.get('realizations', f.min_n)} realizations per cell.",
             _verdict(f), _largest(f)]
    if not f.comparison.empty:
        groups = list(f.comparison.groupby(list(f.cases), sort=False)) if f.cases else [("", f.comparison)]
        lines += [case_line(rows, f.cases, f.bias_limit, noises) for _, rows in groups[:MAX_CASE_LINES]]
        if len(groups) > MAX_CASE_LINES:
            lines.append(f"… and {len(groups) - MAX_CASE_LINES} more cases (see the method comparison table).")
    lines += [_coverage_line(f), few_realizations_note(f), _run_line(out)]
    return [line for line in lines if line]


def status_note(f: Findings) -> str:
    """Why the badge says what it says, in a few words."""
    if not f.count:
        return "no bias or coverage finding"
    parts = []
    if len(f.biases):
        parts.append(f"{len(f.biases)} bias{'es' if len(f.biases) > 1 else ''} beyond {f.bias_limit:.2f} σ")
    if len(f.coverage):
        parts.append(f"{len(f.coverage)} coverage failure{'s' if len(f.coverage) > 1 else ''}")
    return ", ".join(parts)


def comparison_table(f: Findings) -> Table | None:
    """Case × method: worst |bias z| with its parameter and bias %; beyond the limit in red."""
    if f.comparison.empty:
        return None
    cmp = f.comparison.assign(case=[case_name(r, f.cases) for _, r in f.comparison.iterrows()])
    cmp = cmp.assign(text=[f"{_z(r['bias_z'])} ({r['parameter']} {_pct(r['bias_pct'])})" for _, r in cmp.iterrows()])
    frame = cmp.pivot_table(index="case", columns="method", values="text", aggfunc="first", sort=False)
    bad = cmp.pivot_table(index="case", columns="method", values="abs_bias_z", aggfunc="first", sort=False)
    order = sorted(frame.columns, key=lambda m: (KNOWN_METHODS.index(m) if m in KNOWN_METHODS else len(KNOWN_METHODS)))
    frame, bad = frame[order], bad[order]
    frame = frame.reset_index()
    frame.columns = [str(x) for x in frame.columns]
    hl = tuple((i, str(m), "bad") for i, case in enumerate(bad.index) for m in bad.columns
               if np.isfinite(bad.loc[case, m]) and bad.loc[case, m] > f.bias_limit)
    return Table("Method comparison", frame,
                 f"Per case, each method's worst |bias| in Monte Carlo standard errors (its parameter and bias in % "
                 f"of the truth). Red: beyond {f.bias_limit:.2f}, the Bonferroni value for a 1 % chance of any false "
                 f"alarm over the {len(f.tests)} bias tests.", hl)


def _interval(row: pd.Series) -> str:
    return f"[{row['coverage_lo']:.2f}, {row['coverage_hi']:.2f}]"


def biases_table(f: Findings) -> Table | None:
    """The largest biases (beyond the limit), largest first."""
    if f.biases.empty:
        return None
    b = f.biases.head(MAX_TABLE_ROWS)
    frame = pd.DataFrame({**{c: b[c] for c in f.cases}, "method": b["method"], "parameter": b["parameter"],
                          "truth": b["truth"], "bias %": b["bias_pct"], "bias z": b["bias_z"]})
    more = f" The first {MAX_TABLE_ROWS} of {len(f.biases)}." if len(f.biases) > MAX_TABLE_ROWS else ""
    return Table("Largest biases", frame, f"|bias| beyond {f.bias_limit:.2f} Monte Carlo standard errors, largest "
                 "first (error types share the estimates, so each appears once)." + more,
                 tuple((i, "bias z", "bad") for i in range(len(frame))))


def coverage_table(f: Findings) -> Table | None:
    """The coverage failures, farthest from the band first."""
    if f.coverage.empty:
        return None
    c = f.coverage.head(MAX_TABLE_ROWS)
    frame = pd.DataFrame({**{k: c[k] for k in f.cases}, "method": c["method"], "errors": c["errors"],
                          "parameter": c["parameter"], "coverage": c["coverage"],
                          "95 % interval": [_interval(r) for _, r in c.iterrows()], "SE ratio": c["se_ratio"]})
    lo, hi = COVERAGE_BAND
    more = f" The first {MAX_TABLE_ROWS} of {len(f.coverage)}." if len(f.coverage) > MAX_TABLE_ROWS else ""
    return Table("Coverage failures", frame, f"Cells whose exact 95 % binomial interval of coverage lies wholly "
                 f"outside [{lo:.2f}, {hi:.2f}]; SE ratio = mean reported standard error / scatter (1 = honest)."
                 + more, tuple((i, "coverage", "bad") for i in range(len(frame))))


def findings_section(f: Findings) -> Section:
    """The first section: the comparison, the largest biases and the coverage failures."""
    lo, hi = COVERAGE_BAND
    paragraphs = [f"A bias is a finding when it exceeds {f.bias_limit:.2f} Monte Carlo standard errors, the "
                  f"Bonferroni value for a 1 % chance of any false alarm over {len(f.tests)} tests (the rule of "
                  f"the nightly 'unbiased' gate); a coverage is a failure when its exact 95 % binomial interval "
                  f"lies wholly outside [{lo:.2f}, {hi:.2f}] (the band of the nightly 'honest error bounds' gate)."]
    note = few_realizations_note(f)
    if note:
        paragraphs.append(note)
    tables = tuple(t for t in (comparison_table(f), biases_table(f), coverage_table(f)) if t is not None)
    return Section("Findings", tuple(paragraphs), tables)


def setup_section(out: CampaignOutput, setup: Setup) -> Section:
    """What the campaign is, what it flew and each noise definition."""
    c = out.meta["campaign"]
    paragraphs = [p for p in (c.get("description", ""), flown_text(out.truth_scores)) if p]
    if setup.problem:
        noises = ", ".join(str(n) for n in dict.fromkeys(out.scores.get("noise", pd.Series(dtype=str))))
        paragraphs.append(f"Noise definitions not shown: {setup.problem}. Noises: {noises}.")
        return Section("Campaign set-up", tuple(paragraphs))
    table = Table("Noise definitions", noise_table(setup.noises),
                  "Sensor noise levels are standard deviations (white unless stated); output noise is white noise "
                  "added to the equation-error dependent variables. Output error always sees the noisy recording.")
    return Section("Campaign set-up", tuple(paragraphs), (table,))
