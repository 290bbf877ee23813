"""A user's flight data in a layout unlike SIDPAC's (whitespace-separated columns in SI units,
a header line, its own names, an aileron of the opposite sign, time in milliseconds) imports
through a column map and estimates the same as its canonical form."""
from __future__ import annotations

import numpy as np
import pytest

from estimators.methods import make_estimator
from estimators.regressors import Equation
from harness.cli import main
from harness.column_map import import_with_map, recording_to_text
from harness.recording_io import read_recording, write_recording
from maneuvers.recording import Recording
from models.constants import G0_MPS2 as G

FT = 0.3048
PSF_PA = 47.88025898033584
SI_COLUMNS = {  # canonical column -> (the user's header, factor from canonical to the user's unit)
    "t_s": ("time_ms", 1000.0), "alpha_rad": ("AoA", 1.0), "q_rps": ("pitch_rate", 1.0),
    "V_fps": ("TAS", FT), "beta_rad": ("AoS", 1.0), "p_rps": ("roll_rate", 1.0), "r_rps": ("yaw_rate", 1.0),
    "phi_rad": ("roll", 1.0), "theta_rad": ("pitch", 1.0), "psi_rad": ("heading", 1.0),
    "ax_g": ("acc_x", G), "ay_g": ("acc_y", G), "az_g": ("acc_z", G),
    "de_rad": ("elevator", 1.0), "da_rad": ("aileron", -1.0), "dr_rad": ("rudder", 1.0),
    "qbar_psf": ("q_dyn", PSF_PA), "h_ft": ("alt", FT), "mach_1": ("mach", 1.0),
}
MAP = """\
# a user's file: whitespace-separated SI units, one header line
delimiter = "whitespace"
time = "time_ms"
time_scale = 0.001        # ms -> s
negate = ["aileron"]      # this data system's aileron is positive rolling left

[columns]
AoA = "alpha_rad"
AoS = "beta_rad"
TAS = "V_mps"
pitch_rate = "q_rps"
roll_rate = "p_rps"
yaw_rate = "r_rps"
roll = "phi_rad"
pitch = "theta_rad"
heading = "psi_rad"
acc_x = "ax_mps2"
acc_y = "ay_mps2"
acc_z = "az_mps2"
elevator = "de_rad"
aileron = "da_rad"
rudder = "dr_rad"
q_dyn = "qbar_pa"
alt = "h_m"
"""


def _meta_toml(meta) -> str:
    g, m = meta["geometry"], meta["mass"]
    return ("\n[meta]\naircraft = \"F-16 (flown by sidbench)\"\n[meta.geometry]\n"
            + "".join(f"{k} = {v!r}\n" for k, v in g.items())
            + "[meta.mass]\n" + "".join(f"{k} = {v!r}\n" for k, v in m.items()))


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("colmap")
    assert main(["fly", "--maneuver", "three-axis", "--out", str(d / "canonical.csv")]) == 0
    rec = read_recording(d / "canonical.csv")
    recording_to_text(rec, d / "flight.txt", SI_COLUMNS, sep="   ")
    (d / "map.toml").write_text(MAP + _meta_toml(rec.meta), encoding="utf-8")
    return d, rec


def test_whitespace_si_file_imports_through_a_column_map(files, capsys):
    d, rec = files
    assert (d / "flight.txt").read_text().splitlines()[0].split()[:3] == ["time_ms", "AoA", "pitch_rate"]
    assert main(["import", str(d / "flight.txt"), "--column-map", str(d / "map.toml"),
                 "--out", str(d / "imported.csv")]) == 0
    out = capsys.readouterr().out
    assert "aileron negated" in out and "mach" in out and "dropped" in out  # what it changed, said
    imp = read_recording(d / "imported.csv")
    for col in ("t_s", "alpha_rad", "V_fps", "az_g", "de_rad", "da_rad", "qbar_psf", "h_ft"):
        np.testing.assert_allclose(imp.data[col], rec.data[col], rtol=1e-12, atol=1e-12, err_msg=col)
    assert "mach_1" not in imp.data.columns  # not in the map: dropped
    assert imp.meta["import"]["dropped"] == ["mach"]


@pytest.mark.parametrize("dependent,regressors", [("Cm", "alpha,qhat,de"), ("Cl", "beta,phat,rhat,da,dr")])
def test_it_estimates_the_same_as_its_canonical_conversion(files, dependent, regressors):
    d, flown = files
    imp = import_with_map(d / "flight.txt", d / "map.toml")
    # the same file converted by hand: its channels, canonical units, the map's metadata
    cols = [c for c in SI_COLUMNS if c != "mach_1"]
    meta = {k: flown.meta[k] for k in ("format", "geometry", "mass", "sensors", "thrust_offset_ft")}
    by_hand = Recording(flown.data[cols].copy(), meta, name="by-hand").validate("by hand")
    write_recording(by_hand, d / "by-hand.csv")
    rec = read_recording(d / "by-hand.csv")
    eq = Equation.parse(dependent, regressors)
    for method in ("ee-time", "ee-freq"):
        a = make_estimator(method).fit(rec, eq if method != "ee-freq" else Equation.parse(dependent, regressors, False))
        b = make_estimator(method).fit(imp, eq if method != "ee-freq" else Equation.parse(dependent, regressors, False))
        np.testing.assert_allclose(b.params, a.params, rtol=1e-7, atol=1e-12)
        np.testing.assert_allclose(b.bse, a.bse, rtol=1e-6)


def test_mach_and_altitude_give_qbar_when_it_is_not_mapped(files, tmp_path):
    d, rec = files
    text = (d / "map.toml").read_text().replace('q_dyn = "qbar_pa"\n', 'mach = "mach_1"\n')
    (tmp_path / "map.toml").write_text(text)
    imp = import_with_map(d / "flight.txt", tmp_path / "map.toml")
    assert any("from mach and h" in n for n in imp.meta["import_notes"])
    np.testing.assert_allclose(imp.data["qbar_psf"], rec.data["qbar_psf"], rtol=2e-3)


def test_a_bad_column_map_is_one_line_exit_2(files, tmp_path, capsys):
    d, _ = files
    (tmp_path / "bad.toml").write_text(MAP.replace('AoA = "alpha_rad"', 'AngleOfAttack = "alpha_rad"'))
    assert main(["import", str(d / "flight.txt"), "--column-map", str(tmp_path / "bad.toml"),
                 "--out", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "AngleOfAttack" in err and "header" in err
    assert not (tmp_path / "x.csv").exists()
