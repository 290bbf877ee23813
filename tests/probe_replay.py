"""Helpers of the probe-replay tests: fly a kept probe's draw (tests/probe/gen.py, jsbsim and
numpy only) and diagnose it against its own package aircraft."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from harness.diagnosis.run import diagnose


def _found(result):
    return [(f["parameter"], round(f["estimate"], 4)) for f in result["findings"] if f["effect"] != "none"]


def _probe(seed: int, folder: Path) -> dict:
    """Fly the kept probe's draw ``seed`` (tests/probe/gen.py: jsbsim and numpy only) into
    ``folder`` (id.csv, val.csv and their metadata) and return its truth.json."""
    import subprocess
    import sys
    subprocess.run([sys.executable, str(Path(__file__).parent / "probe" / "gen.py"), str(seed), str(folder)],
                   check=True, capture_output=True)
    return json.loads((folder / "truth.json").read_text())


def _diagnosed_probe(seed: int, folder: Path, validation: bool = True, **options) -> tuple[dict, dict]:
    """The kept probe's draw ``seed`` (:func:`_probe`) and its diagnosis against its own aircraft."""
    truth = _probe(seed, folder)
    result = diagnose(_package_xml(truth["aircraft"]), folder / "id.csv", folder / "out",
                      folder / "val.csv" if validation else None, **options)
    return truth, result


def _named_alone(result: dict, truth: dict, rel: float = 0.25) -> None:
    """The planted parameter is the only finding, its size within ``rel`` of the truth."""
    found = _found(result)
    assert [p for p, _ in found] == [truth["parameter"]], found
    assert found[0][1] == pytest.approx(truth["truth"], rel=rel)


def _withheld_for(result: dict, parameter: str, words: str) -> None:
    """Candidate ``parameter`` is not named, its reason saying ``words``."""
    c = next(c for c in result["candidates"] if c["parameter"] == parameter)
    assert not c.get("selected") and words in c["reason"], c["reason"]


def _package_xml(model: str) -> str:
    """The package aircraft ``model``'s XML path, its surfaces registered with the script (the
    elevator, left aileron and rudder positions, as the package's aircraft name them)."""
    import jsbsim

    import independent_script
    independent_script.SURFACE_PROPERTIES.setdefault(
        model, ("fcs/elevator-pos-rad", "fcs/left-aileron-pos-rad", "fcs/rudder-pos-rad"))
    return str(Path(jsbsim.get_default_root_dir()) / "aircraft" / model / f"{model}.xml")
