"""Must-show 3 of the calibration issue: the validation RMS of each case's affected output after
the equation-error sizes and after the calibrated ones, case by case, and which the diagnosis
kept (:mod:`harness.diagnosis.refine`).

``python -m harness.diagnosis.refine_table gallery OUT [--seed N ...]`` writes the gallery's
recordings for each seed, diagnoses them (calibration on) and prints the table;
``python -m harness.diagnosis.refine_table sweep DIR`` prints it from a diagnosis or outside
sweep's ``DIR/results/*.json`` (their ``calibration`` column). Both write ``table.json`` beside.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from harness.atomic import write_text_atomic
from harness.calibrate.gallery import AFFECTED
from harness.diagnosis.gallery import CASES, write_case
from harness.diagnosis.refine import validation_rms_pair


def gallery_rows(out: Path, seed: int, workers: int = 2) -> list[dict]:
    """The gallery at noise seed ``seed``: each case written, diagnosed with calibration, and
    its row (``case``, ``seed``, the diagnosis's ``calibration`` column for the case's
    affected output, the parameters before and after)."""
    from harness.diagnosis.run import diagnose
    rows = []
    for c in CASES:
        paths = write_case(c, out / f"seed{seed}" / "recordings", seed=seed)
        result = diagnose("f16", paths["identification"], out / f"seed{seed}" / "diagnoses" / c.name,
                          paths["validation"], calibrate_workers=workers)
        block = result["calibration"]
        rows.append({"case": c.name, "seed": seed, "calibration": validation_rms_pair(block, AFFECTED[c.name]),
                     "parameters": block.get("parameters", []), "reason": block["reason"],
                     "seconds": result["timing_s"].get("calibration")})
    return rows


def sweep_rows(folder: Path) -> list[dict]:
    """The rows of a diagnosis or outside sweep (``folder/results/*.json``), by case name."""
    rows = []
    for path in sorted((folder / "results").glob("*.json")):
        r = json.loads(path.read_text())
        rows.append({"case": r["case"], "seed": None, "calibration": r.get("calibration"), "error": r.get("error")})
    return rows


def _change(ee: float, cal: float) -> str:
    return f"{100 * (cal / ee - 1):+.1f} %" if ee else "–"


def summary(rows: list[dict]) -> dict:
    """Totals over the rows with a calibration: how many used, how many calibrated fits were
    better / worse than the equation-error ones, and the summed RMS before and after (as kept)."""
    done = [r["calibration"] for r in rows if r.get("calibration") and r["calibration"]["equation_error"]
            and r["calibration"]["calibrated"] is not None]
    kept = [c["calibrated"] if c["used"] else c["equation_error"] for c in done]
    return {"cases": len(rows), "calibrated": len(done), "used": sum(c["used"] for c in done),
            "calibrated_better": sum(c["calibrated"] < c["equation_error"] for c in done),
            "calibrated_worse": sum(c["calibrated"] > c["equation_error"] for c in done),
            "kept_worse": sum(k > c["equation_error"] for k, c in zip(kept, done)),
            "sum_equation_error": sum(c["equation_error"] for c in done),
            "sum_calibrated": sum(c["calibrated"] for c in done), "sum_kept": sum(kept),
            "nothing_to_calibrate": len(rows) - len(done)}


def markdown(rows: list[dict]) -> str:
    """One line per case that had a term to calibrate, then the totals."""
    lines = ["| case | output | EE sizes | calibrated | change | used |", "| --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        c = r.get("calibration")
        if not c or not c["equation_error"] or c["calibrated"] is None:
            continue
        name = f"`{r['case']}`" + (f" (seed {r['seed']})" if r.get("seed") else "")
        lines.append(f"| {name} | {c['channel']} | {c['equation_error']:.4g} | {c['calibrated']:.4g} | "
                     f"{_change(c['equation_error'], c['calibrated'])} | {'yes' if c['used'] else 'no'} |")
    s = summary(rows)
    lines += ["", f"{s['calibrated']} of {s['cases']} cases had a term to calibrate; the calibrated sizes were used in "
                  f"{s['used']}, fitted the affected output better in {s['calibrated_better']} and worse in "
                  f"{s['calibrated_worse']}; as kept, worse than the equation-error sizes in {s['kept_worse']}. "
                  f"Summed RMS (mixed units): EE sizes {s['sum_equation_error']:.4g}, calibrated "
                  f"{s['sum_calibrated']:.4g}, as kept {s['sum_kept']:.4g}."]
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> int:
    kind, folder = argv[0], Path(argv[1])
    if kind == "gallery":
        seeds = [int(x) for x in argv[argv.index("--seed") + 1:]] if "--seed" in argv else [1]
        rows = [r for s in seeds for r in gallery_rows(folder, s)]
    else:
        rows = sweep_rows(folder)
    write_text_atomic(folder / "table.json", json.dumps({"rows": rows, "summary": summary(rows)}, indent=1))
    print(markdown(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
