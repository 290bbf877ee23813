"""The diagnosis refined, on the concealed-effect gallery: for each case, the diagnosis's
added terms at their equation-error sizes (``calibrate``'s start, ``--parameters auto``) against
the same terms calibrated in the loop; the validation RMS error of every output, before
(equation-error sizes) and after. ``python -m harness.calibrate.gallery OUT [--seed N] [CASE ...]``
writes OUT/gallery-calibration.json and prints a Markdown table."""
from __future__ import annotations

import json
import sys
from pathlib import Path

from harness.atomic import write_text_atomic
from harness.calibrate.problem import CalibrationError
from harness.calibrate.run import calibrate
from harness.diagnosis.gallery import CASES, case, write_case

AFFECTED = {"unsteady_alphadot": "q", "control_delay": "q", "nonlinear_alpha": "q", "coefficient_error": "q",
            "cg_offset": "q", "sensor_offset": "az", "sensor_bias": "alpha", "structural_mode": "q",
            "turbulence": "r", "none": "q"}


def refine_case(name: str, out: Path, seed: int = 1, workers: int = 2) -> dict:
    """One gallery case: recordings written, diagnosed, its terms calibrated."""
    c = case(name)
    paths = write_case(c, out / "recordings", seed=seed)
    row = {"case": name, "truth": c.truth, "parameter": c.parameter, "affected": AFFECTED[name]}
    try:
        r = calibrate("f16", paths["identification"], "auto", validation=paths["validation"], workers=workers,
                      hold="sample")
    except CalibrationError as exc:
        return row | {"calibrated": None, "reason": str(exc)}
    ch = AFFECTED[name]
    row |= {"calibrated": r.parameter_table(), "iterations": r.iterations, "converged": r.converged,
            "seconds": r.seconds, "validation_rms_ee": r.fit_before["validation"][ch]["rms"],
            "validation_rms_calibrated": r.fit_after["validation"][ch]["rms"],
            "validation_all": {k: [r.fit_before["validation"][k]["rms"], r.fit_after["validation"][k]["rms"]]
                               for k in r.outputs}}
    return row


def table(rows: list[dict]) -> str:
    lines = ["| case | truth | equation error → calibrated (± s.e.) | validation RMS of the affected output, EE sizes → calibrated |",
             "| --- | --- | --- | --- |"]
    for r in rows:
        if r["calibrated"] is None:
            lines.append(f"| `{r['case']}` | {r['truth']:.3g} | no aircraft term to calibrate | — |")
            continue
        est = "; ".join(f"{p['name']} {p['start']:.3g} → {p['estimate']:.3g} ± {p['std_error']:.2g}"
                        for p in r["calibrated"])
        b, a = r["validation_rms_ee"], r["validation_rms_calibrated"]
        lines.append(f"| `{r['case']}` | {r['parameter']} = {r['truth']:.3g} | {est} | {r['affected']} {b:.3g} → "
                     f"{a:.3g} ({100 * (a / b - 1):+.0f} %) |")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    seed = 1
    if "--seed" in argv:
        i = argv.index("--seed")
        seed = int(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    out = Path(argv[0])
    names = argv[1:] or [c.name for c in CASES]
    rows = [refine_case(n, out, seed=seed) for n in names]
    write_text_atomic(out / "gallery-calibration.json", json.dumps(rows, indent=1, default=float))
    print(table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
