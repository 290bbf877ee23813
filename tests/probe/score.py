#!/usr/bin/env python
"""usage: score.py TAG -- score $PROBE_OUT/TAG/*/ (default /tmp/p; truth.json, diag/findings.json, exit status);
writes $PROBE_OUT/TAG/score.json"""
import json
import math
import os
import sys
from pathlib import Path

ALIAS = {("sensor_offset", "offset_x"): ("sensor_offset", "x_accelerometer"),
         ("sensor_offset", "y_accelerometer"): ("sensor_offset", "offset_y"),
         ("sensor_offset", "z_accelerometer"): ("sensor_offset", "offset_z")}


def key(effect, parameter):
    k = (effect or "", parameter or "")
    return ALIAS.get(k, k)


def size_of(f):
    est = f.get("estimate")
    ev = f.get("evidence")
    if f.get("effect") == "coefficient_error" and isinstance(ev, dict) and ev.get("change") is not None:
        est = ev["change"]
    return est


def fmt(x):
    if x is None:
        return "null"
    try:
        return f"{x:.4g}"
    except (TypeError, ValueError):
        return str(x)


def last_line(path):
    try:
        lines = [ln.strip() for ln in path.read_text(errors="replace").splitlines() if ln.strip()]
        return lines[-1] if lines else ""
    except OSError:
        return ""


def main(tag):
    base = Path(os.environ.get("PROBE_OUT", "/tmp/p")) / tag
    dirs = sorted((d for d in base.iterdir() if d.is_dir() and d.name.lstrip("-").isdigit()), key=lambda d: int(d.name))
    rows, falses, errors, skips = [], [], [], []
    n_null = n_null_ok = n_eff = n_a = n_b = n_b_eligible = 0
    for d in dirs:
        seed = int(d.name)
        if (d / "skip.json").exists():
            sk = json.loads((d / "skip.json").read_text())
            skips.append({"seed": seed, "reason": sk.get("reason", "")})
            print(f"{seed:>6}  SKIP  {sk.get('aircraft', '?')}  {sk.get('reason', '')}")
            continue
        if not (d / "truth.json").exists():
            msg = last_line(d / "gen.err") or "no truth.json"
            errors.append({"seed": seed, "stage": "gen", "rc": (d / "gen.rc").read_text().strip() if (d / "gen.rc").exists() else "?", "last": msg})
            print(f"{seed:>6}  GEN-ERROR  {msg}")
            continue
        tr = json.loads((d / "truth.json").read_text())
        rc = (d / "diag.rc").read_text().strip() if (d / "diag.rc").exists() else "missing"
        cond = f"h={tr['h_ft']:.0f}ft V={tr['V_fps']:.0f}fps"
        planted = key(tr["effect"], tr["parameter"])
        is_null = tr["effect"] == "none"
        rec = {"seed": seed, "aircraft": tr["aircraft"], "condition": cond, "kind": tr["kind"], "effect": tr["effect"],
               "parameter": tr["parameter"], "truth": tr["truth"], "channel": tr["channel"], "rc": rc,
               "description": tr["description"]}
        planted_txt = "none" if is_null else f"{tr['effect']}:{tr['parameter']}={fmt(tr['truth'])}"
        fj = d / "diag" / "findings.json"
        if rc != "0" or not fj.exists():
            msg = last_line(d / "diag.err")
            errors.append({"seed": seed, "stage": "diagnose", "rc": rc, "last": msg, "description": tr["description"]})
            rec["verdict"] = ["ERROR"]
            rows.append(rec)
            if is_null:
                n_null += 1
            else:
                n_eff += 1
            print(f"{seed:>6}  {tr['aircraft']:<6} {cond:<22} {tr['kind']:<10} {planted_txt:<45} -> ERROR rc={rc}: {msg[:120]}")
            continue
        findings = json.loads(fj.read_text()).get("findings", [])
        first = findings[0] if findings else {"effect": "(no findings)", "parameter": ""}
        fk = key(first.get("effect"), first.get("parameter"))
        est, se = size_of(first), first.get("std_error")
        flags = []
        fl = []
        if is_null:
            n_null += 1
            fl = [f for f in findings if f.get("effect") != "none"]
            if not fl and findings and all(f.get("effect") == "none" for f in findings):
                n_null_ok += 1
                flags.append("NULL-OK")
            else:
                flags.append("NULL-MISSED")
        else:
            n_eff += 1
            a = fk == planted
            if a:
                n_a += 1
                flags.append("A")
                if tr["truth"] is not None:
                    n_b_eligible += 1
                    ok = False
                    try:
                        err = abs(float(est) - tr["truth"])
                        ok = (se is not None and math.isfinite(float(se)) and err <= 2 * float(se)) or err <= 0.25 * abs(tr["truth"])
                    except (TypeError, ValueError):
                        pass
                    if ok:
                        n_b += 1
                        flags.append("B")
                    else:
                        flags.append("b-miss")
            else:
                flags.append("a-miss")
            fl = [f for f in findings if f.get("effect") != "none" and key(f.get("effect"), f.get("parameter")) != planted]
        for f in fl:
            falses.append({"seed": seed, "finding": f"{f.get('effect')}:{f.get('parameter')}={fmt(size_of(f))}±{fmt(f.get('std_error'))}",
                           "planted": planted_txt, "description": tr["description"]})
        if fl:
            flags.append(f"FALSE×{len(fl)}")
        rec.update(first_effect=first.get("effect"), first_parameter=first.get("parameter"), estimate=est, std_error=se,
                   n_findings=len(findings), all_findings=[f"{f.get('effect')}:{f.get('parameter')}" for f in findings],
                   verdict=flags)
        rows.append(rec)
        first_txt = f"{first.get('effect')}:{first.get('parameter')}={fmt(est)}±{fmt(se)}" if first.get("effect") != "none" else "none"
        more = f" (+{len(findings) - 1})" if len(findings) > 1 else ""
        print(f"{seed:>6}  {tr['aircraft']:<6} {cond:<22} {tr['kind']:<10} {planted_txt:<45} -> {first_txt}{more}  [{' '.join(flags)}]")
    print()
    print(f"nulls answered none: {n_null_ok} of {n_null}")
    print(f"right first (a): {n_a} of {n_eff} effects")
    print(f"size within 2 se or 25 % (b): {n_b} of {n_b_eligible} right-first cases with a size ({n_b} of {n_eff} effects)")
    print(f"false findings: {len(falses)}")
    for f in falses:
        print(f"  seed {f['seed']}: {f['finding']}  (planted {f['planted']})\n      {f['description']}")
    print(f"refusals/errors: {len(errors)}")
    for e in errors:
        print(f"  seed {e['seed']} [{e['stage']} rc={e['rc']}]: {e['last']}")
    print(f"skips: {len(skips)} of {len(dirs)}")
    for s in skips:
        print(f"  seed {s['seed']}: {s['reason']}")
    out = {"tag": tag, "cases": rows, "false_findings": falses, "errors": errors, "skips": skips,
           "totals": {"nulls": n_null, "nulls_none": n_null_ok, "effects": n_eff, "right_first": n_a,
                      "size_eligible": n_b_eligible, "size_ok": n_b, "false_findings": len(falses),
                      "errors": len(errors), "skips": len(skips), "seeds": len(dirs)}}
    (base / "score.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
