"""The JSBSim DHC6 (Twin Otter): surfaces, mass rewrite, trim with running turboprops, flight."""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from models.aircraft import TRIM_MOMENT_PROPERTIES, Aircraft, dhc6_tree, load_fdm, nominal_tree
from models.conditions import condition_for
from models.flight import fly
from models.mass import MassProperties, loaded_cg_in, mass_root, set_mass_properties
from models.trim import set_initial_condition, trim

DT = 1 / 120
# Means of the SIDPAC Twin Otter record 017 (mass_slug, Iy and Iz vary by < 0.01 %).
RECORD_017 = MassProperties(mass_slug=339.2962548451548, Ix_slugft2=20902.0, Iy_slugft2=24256.396603396603,
                            Iz_slugft2=38462.796203796206, Ixz_slugft2=1127.0)
DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "sidpac"


def _loaded(model: str, root=None, name=None):
    fdm = load_fdm(Aircraft(model), DT, root=root, name=name)
    set_initial_condition(fdm, 6000.0, 240.0)
    fdm["propulsion/set-running"] = -1
    fdm.run_ic()
    return fdm


def _trimmed(mass: MassProperties | None = None):
    ac = Aircraft("dhc6")
    root, name = mass_root("dhc6", mass) if mass is not None else (None, None)
    fdm = load_fdm(ac, DT, root=root, name=name)
    return ac, fdm, trim(fdm, ac, condition_for("dhc6"))


def _doublets(t: np.ndarray) -> dict[str, np.ndarray]:
    def doublet(t0: float, a: float) -> np.ndarray:
        return a * (((t >= t0) & (t < t0 + 1)).astype(float) - ((t >= t0 + 1) & (t < t0 + 2)))
    return {"da": doublet(1.0, 0.02), "dr": doublet(5.0, 0.02)}


@pytest.mark.parametrize("model", ["dhc6", "f16"])
def test_mass_rewrite_gives_exactly_the_requested_mass_and_inertia(model):
    fdm0 = _loaded(model)
    cg0 = [fdm0[f"inertia/cg-{a}-in"] for a in "xyz"]
    root, name = mass_root(model, RECORD_017)
    fdm = _loaded(model, root, name)
    assert fdm["inertia/mass-slugs"] == pytest.approx(RECORD_017.mass_slug, rel=1e-13)
    assert fdm["inertia/ixx-slugs_ft2"] == pytest.approx(RECORD_017.Ix_slugft2, rel=1e-13)
    assert fdm["inertia/iyy-slugs_ft2"] == pytest.approx(RECORD_017.Iy_slugft2, rel=1e-13)
    assert fdm["inertia/izz-slugs_ft2"] == pytest.approx(RECORD_017.Iz_slugft2, rel=1e-13)
    # JSBSim's matrix holds -Ixz (the seed's sign), as models.trim.read_trim_point reads it
    assert -fdm["inertia/ixz-slugs_ft2"] == pytest.approx(RECORD_017.Ixz_slugft2, rel=1e-12)
    assert fdm["inertia/ixy-slugs_ft2"] == 0.0 and fdm["inertia/iyz-slugs_ft2"] == 0.0
    # the c.g. stays where the package's loading put it
    assert [fdm[f"inertia/cg-{a}-in"] for a in "xyz"] == pytest.approx(cg0, abs=1e-9)
    assert list(loaded_cg_in(nominal_tree(model))) == pytest.approx(cg0, abs=1e-9)


def test_mass_rewrite_is_pure_and_refuses_a_weight_below_the_fuel():
    tree = nominal_tree("dhc6")
    before = ET.tostring(tree.getroot())
    out = set_mass_properties(tree, RECORD_017)
    assert ET.tostring(tree.getroot()) == before
    mb = out.getroot().find("mass_balance")
    assert mb.findall("pointmass") == []
    assert float(mb.find("ixz").text) == -RECORD_017.Ixz_slugft2
    with pytest.raises(ValueError, match="fuel"):
        set_mass_properties(tree, MassProperties(30.0, 1.0, 1.0, 1.0, 0.0))  # 965 lb < 1784 lb fuel


def test_elevator_write_drives_the_magnitude_the_drag_reads_with_the_fcs_off():
    fdm = _loaded("dhc6")
    fdm["simulation/models/FGFCS/enabled"] = 0
    props = Aircraft("dhc6").surfaces
    assert props == {"de": "fcs/elevator-pos-rad", "da": "fcs/left-aileron-pos-rad", "dr": "fcs/rudder-pos-rad"}
    fdm[props["de"]] = -0.05
    fdm.run()
    assert fdm["fcs/mag-elevator-pos-rad"] == 0.05


def test_slipstream_pitching_moment_reads_the_engines_not_an_fcs_system():
    cmt = next(f for f in dhc6_tree().getroot().iter("function") if f.get("name") == "aero/coefficient/CmT")
    props = [p.text.strip() for p in cmt.iter("property")]
    assert "systems/propulsion/thrust-coefficient" not in props
    assert {"propulsion/engine[0]/thrust-coefficient", "propulsion/engine[1]/thrust-coefficient"} <= set(props)


@pytest.mark.parametrize("mass", [None, RECORD_017], ids=["package-mass", "record-017-mass"])
def test_dhc6_trims_and_holds_its_trim_in_flight(mass):
    ac, fdm, tp = _trimmed(mass)
    cond = condition_for("dhc6")
    assert tp.V_fps == pytest.approx(cond.V_fps) and tp.h_ft == pytest.approx(cond.h_ft)
    assert abs(tp.alpha_rad) < math.radians(3) and abs(tp.phi_rad) < 1e-3 and abs(tp.beta_rad) < 1e-6
    assert 0.3 < tp.throttle < 1.0 and tp.thrust_lbf > 500
    assert 0.0 < tp.de_rad < 0.2  # trailing edge down
    if mass is not None:
        assert tp.mass_slug == pytest.approx(mass.mass_slug, rel=1e-12)
        assert tp.Ixz_slugft2 == pytest.approx(mass.Ixz_slugft2, rel=1e-12)
    # the trim aid is off, and the engines run with the trimmed thrust and their torque
    assert all(fdm[p] == 0.0 for p in TRIM_MOMENT_PROPERTIES.values())
    assert fdm["propulsion/engine[0]/power-hp"] > 100
    assert fdm["moments/l-prop-lbsft"] < -1000
    c = fly(fdm, ac, tp, lambda t: {}, 2.0).channels
    for k in ("pdot_rps2", "qdot_rps2", "rdot_rps2"):
        assert np.abs(c[k]).max() < 1e-5, k
    for k in ("p_rps", "q_rps", "r_rps"):
        assert np.abs(c[k]).max() < 1e-5, k
    assert np.ptp(c["thrust_lbf"]) < 0.01 * tp.thrust_lbf
    assert np.ptp(c["V_fps"]) < 0.05


def test_dhc6_flies_ten_seconds_open_loop_with_lateral_doublets():
    ac, fdm, tp = _trimmed(RECORD_017)
    h = fly(fdm, ac, tp, _doublets, 10.0)
    c = h.channels
    assert all(np.isfinite(v).all() for v in c.values())
    assert all(np.isfinite(v).all() for v in h.truth.values())
    assert np.ptp(c["da_rad"]) == pytest.approx(0.04) and np.ptp(c["dr_rad"]) == pytest.approx(0.04)
    assert np.abs(c["phi_rad"]).max() < math.radians(30)
    assert np.abs(c["beta_rad"]).max() < math.radians(5)
    assert np.abs(c["V_fps"] - tp.V_fps).max() < 10


def test_condition_is_the_twin_otter_record_017_mean():
    cond = condition_for("dhc6")
    assert cond.name == "twin-otter-017"
    path = DATA / "totter_f1_017_data.mat"
    if not path.is_file():
        pytest.skip(f"{path} is absent")
    from harness.sidpac import import_sidpac
    rec = import_sidpac(path)
    assert cond.V_fps == pytest.approx(rec.channel("V").mean(), abs=0.5)
    assert cond.h_ft == pytest.approx(rec.channel("h").mean(), abs=5)
    mean = {k: float(np.mean(v)) for k, v in rec.mass_at().items()}
    assert MassProperties.from_mapping(mean) == RECORD_017


def test_the_model_along_a_dive_follows_the_propeller_the_flight_had():
    """The DHC6 flown into a spiral dive (all three surfaces at once, 230 to 370 ft/s):
    evaluated along the flown states (and α̇), the model's aerodynamic C_m is JSBSim's own in
    flight to 0.001. ``run_ic`` alone kept the propeller at its trim rpm, windmilling at the dive's
    speed, and its slipstream moment (CmT) 0.025 off (models.replay.aero_along). The
    propeller moments beyond the thrust line (gyroscopic) are reported apart."""
    from maneuvers.combine import Sequence, Simultaneous
    from maneuvers.fly import FlightSpec, fly_maneuver
    from maneuvers.multistep import multistep
    from models.replay import InitialCondition, aero_along
    parts = (multistep("3-2-1-1", "de", 2.0, 0.5), multistep("doublet", "da", 2.0, 1.0),
             multistep("2-1-1", "dr", 2.0, 1.0))
    rec = fly_maneuver(FlightSpec(input=Sequence((Simultaneous(parts),), gap_s=2.0), aircraft=Aircraft("dhc6"),
                                  condition="h=6000,V=230", duration_s=30.0, sample_rate_hz=10.0))
    d = rec.data
    assert d["V_fps"].max() > 360.0
    states = {k: d[f"{k}_{u}"].to_numpy() for k, u in (("V", "fps"), ("alpha", "rad"), ("beta", "rad"), ("p", "rps"),
                                                      ("q", "rps"), ("r", "rps"), ("phi", "rad"), ("theta", "rad"),
                                                      ("h", "ft"))}
    surfaces = {s: d[f"{s}_rad"].to_numpy() for s in ("de", "da", "dr")}
    along = aero_along(Aircraft("dhc6"), InitialCondition(6000.0, 230.0), states, surfaces,
                       d["truth_alphadot_rps"].to_numpy())
    aero_cm = along.coefficients["Cm"] - along.propulsion["Cm"]
    assert np.max(np.abs(aero_cm - d["truth_Cm_1"].to_numpy())) < 0.001  # 6e-4; 0.027 unsettled
    assert np.max(np.abs(along.propulsion["Cm"])) > 0.002  # a yaw rate of 0.08 rad/s pitches the propellers


def test_propeller_gyroscopic_moment_is_the_spin_times_the_yaw_rate():
    """models.truth.CoefficientProbe.propulsion_moments: a yaw rate r pitches the DHC6 by its
    two propellers' angular momentum, 2·I·Ω·r (I = 25.1034 slug·ft², Propeller.xml; Ω its
    rpm), beyond the thrust line; nothing beyond it at trim; nothing for a jet."""
    from models.replay import InitialCondition, _instance
    from models.truth import CoefficientProbe, differencing_instance
    for model, ic in (("dhc6", InitialCondition(6000.0, 230.0)), ("f16", InitialCondition(10000.0, 420.0))):
        ac = Aircraft(model)
        cond, kwargs = _instance(ac, ic, None)
        fdm, tp, gated = differencing_instance(ac, cond, **kwargs)
        probe = CoefficientProbe(fdm, ac, tp, gated)
        probe.evaluate()
        assert probe.propulsion_moments()["Cm"] == pytest.approx(0.0, abs=1e-12)
        probe.evaluate(rhat=0.1 * tp.b_ft / (2 * tp.V_fps))
        qSc = fdm["aero/qbar-psf"] * tp.S_ft2 * tp.cbar_ft
        pitch = probe.propulsion_moments()["Cm"] * qSc
        if model == "f16":
            assert pitch == 0.0
            continue
        spin = fdm["propulsion/engine[0]/propeller-rpm"] * 2 * math.pi / 60
        assert abs(pitch) == pytest.approx(2 * 25.1034 * spin * 0.1, rel=1e-3)
