"""A calibration's output folder: calibration.json, model/ (the calibrated aircraft XML for
stock JSBSim, checked to load and fly there) and series/ (the time histories the report
draws). Every file is written whole or not at all (:mod:`harness.atomic`)."""
from __future__ import annotations

import json
import math
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pandas as pd

from harness.atomic import ensure_folder, jsonable, write_atomic, write_text_atomic
from harness.calibrate.run import CalibrationResult
from models.aircraft import new_fdm
from models.jsbsim_root import write_root

STOCK_CHECK_S = 5.0


def fly_stock(tree: ET.ElementTree, source: Path, name: str, h_ft: float, V_fps: float,
              seconds: float = STOCK_CHECK_S) -> dict:
    """Load ``tree`` in a plain JSBSim (FCS, systems and actuators on: no sidbench flight loop),
    start it at ``h_ft``, ``V_fps`` and run ``seconds``; what happened, as a dict."""
    with tempfile.TemporaryDirectory(prefix="sidbench-stock-") as d:
        write_root(Path(d), name, tree, source)
        try:
            fdm = new_fdm(Path(d), name, 1 / 120)
        except RuntimeError as exc:
            return {"loads": False, "flies": False, "detail": str(exc)}
        fdm["ic/h-sl-ft"] = h_ft
        fdm["ic/vt-fps"] = V_fps
        fdm.run_ic()
        frames = int(round(seconds * 120))
        for _ in range(frames):
            fdm.run()
        finite = all(math.isfinite(fdm[p]) for p in ("velocities/vt-fps", "aero/alpha-rad", "velocities/q-rad_sec"))
    return {"loads": True, "flies": bool(finite), "seconds": seconds, "engine": "stock jsbsim "
            "(FCS enabled, the aircraft's own systems and the calibration's actuator delays running)"}




def write_calibration(result: CalibrationResult, out: str | Path) -> dict:
    """Write ``out``/calibration.json, ``out``/model/<aircraft>-calibrated.xml and
    ``out``/series/<role>-<k>.parquet; returns calibration.json's content."""
    out = ensure_folder(out, "--out folder")
    model_dir = ensure_folder(out / "model", "model folder")
    tree = result.calibrated_tree()
    stem = Path(result.base.source).stem
    target = model_dir / f"{stem}-calibrated.xml"
    write_atomic(target, lambda fh: tree.write(fh, encoding="utf-8", xml_declaration=True))
    h, V = result.inputs.get("start_h_ft", 10_000.0), result.inputs.get("start_V_fps", 400.0)
    stock = fly_stock(tree, Path(result.base.source), f"{stem}-calibrated", h, V)
    series_dir = ensure_folder(out / "series", "series folder")
    files = []
    for role, items in result.series.items():
        for k, item in enumerate(items):
            df = pd.DataFrame(item["columns"])
            path = series_dir / f"{role}-{k + 1}.parquet"
            write_atomic(path, lambda fh, df=df: df.to_parquet(fh, index=False))
            files.append({"role": role, "recording": item["name"], "file": str(path.relative_to(out))})
    doc = result.as_json()
    doc["model"] = {"xml": str(target.relative_to(out)), "base": result.base.model,
                    "engines_and_systems": f"those of {result.base.source} (linked, not copied)", "stock_check": stock,
                    "delays": "JSBSim <actuator> delays in a <system> of their own (rounded down to whole frames)"}
    doc["series"] = files
    doc = jsonable(doc)
    write_text_atomic(out / "calibration.json", json.dumps(doc, indent=1))
    return doc
