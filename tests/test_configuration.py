"""The aircraft flies as a flight-test aircraft does (gear up, clean), trims anywhere in the
envelope, and records a continuous heading (issue 11, parts 1-3)."""
from __future__ import annotations

import math

import jsbsim
import numpy as np
import pytest

from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.inputs import default_three_axis_input
from models.aircraft import Aircraft, load_fdm
from models.conditions import FlightCondition, condition_for, parse_condition
from models.trim import TrimError, trim


@pytest.fixture(scope="module")
def three_axis():
    """A three-axis F-16 recording at the default condition (de 2-1-1-2, da doublet, dr 2-1-1)."""
    return fly_maneuver(FlightSpec(input=default_three_axis_input()))


def _independent_f16(h_ft: float, V_fps: float, dt: float) -> jsbsim.FGFDMExec:
    """The package's F-16, set up here without the project's models package: gear retracted
    as ../shared/jsbsim-notes.md describes, trimmed by JSBSim (longitudinal)."""
    jsbsim.FGJSBBase().debug_lvl = 0
    fdm = jsbsim.FGFDMExec(None)
    fdm.set_debug_level(0)
    assert fdm.load_model("f16")
    fdm.set_dt(dt)
    fdm["ic/lat-gc-deg"] = 0.0
    fdm["ic/long-gc-deg"] = 0.0
    fdm["ic/psi-true-deg"] = 0.0
    fdm["ic/h-sl-ft"] = h_ft
    fdm["ic/vt-fps"] = V_fps
    fdm["ic/gamma-deg"] = 0.0
    fdm["gear/gear-cmd-norm"] = 0.0
    fdm["propulsion/set-running"] = -1
    fdm.run_ic()
    fdm["gear/gear-pos-norm"] = 0.0
    fdm.do_trim(0)
    fdm["propulsion/fuel_freeze"] = 1
    return fdm


def test_f16_trims_clean_at_the_default_condition(three_axis):
    meta = three_axis.meta
    config = meta["simulation"]["configuration"]
    assert config["gear"] == "up and locked"
    assert config["positions"]["gear/gear-pos-norm"] == 0.0
    assert config["positions"]["fcs/speedbrake-pos-norm"] == 0.0
    # the clean aircraft's trim thrust (the notes: about 2,150 lbf; gear down about 3,380)
    assert 2_000.0 < meta["trim"]["thrust_lbf"] < 2_300.0
    fdm = _independent_f16(meta["trim"]["h_ft"], meta["trim"]["V_fps"], 1 / 150)
    assert fdm["aero/coefficient/CDgear"] == 0.0
    assert meta["trim"]["thrust_lbf"] == pytest.approx(fdm["forces/fbx-prop-lbs"], rel=1e-3)
    assert meta["trim"]["alpha_rad"] == pytest.approx(fdm["aero/alpha-rad"], abs=1e-5)


def test_independent_replay_returns_the_recorded_pitch_rate(three_axis):
    """Stock JSBSim F-16, gear retracted, FCS disabled, driven by the recording's surfaces
    (zero-order hold on the simulation frames): the recorded q comes back within 3 % of its
    excursion, so the recording is of the aircraft a flight-test team flies."""
    rec = three_axis
    sim = rec.meta["simulation"]
    n_sub = round(sim["sim_rate_hz"] / sim["sample_rate_hz"])
    fdm = _independent_f16(rec.meta["trim"]["h_ft"], rec.meta["trim"]["V_fps"], 1.0 / sim["sim_rate_hz"])
    fdm["simulation/models/FGFCS/enabled"] = 0
    d = rec.data
    surfaces = {"fcs/elevator-pos-rad": d["de_rad"].to_numpy(), "fcs/aileron-pos-rad": d["da_rad"].to_numpy(),
                "fcs/rudder-pos-rad": d["dr_rad"].to_numpy()}
    q = [fdm["velocities/q-rad_sec"]]
    for k in range(1, len(d)):
        for j in range(n_sub):
            f = (k - 1) * n_sub + j + 1
            sample = -(-f // n_sub)  # the sample whose value the frame flies (ceil(f / n_sub))
            for prop, values in surfaces.items():
                fdm[prop] = float(values[sample])
            fdm.run()
        q.append(fdm["velocities/q-rad_sec"])
    q_rec = d["q_rps"].to_numpy()
    excursion = q_rec.max() - q_rec.min()
    assert np.max(np.abs(np.asarray(q) - q_rec)) <= 0.03 * excursion


def test_heading_is_continuous_and_the_reader_takes_either_convention(three_axis, tmp_path):
    from harness.recording_io import read_recording, write_recording

    psi = three_axis.data["psi_rad"].to_numpy()
    assert np.max(np.abs(np.diff(psi))) < 0.05  # no 2*pi jump where the rudder yaws it through 0
    assert psi.min() < 0.0 < psi.max() or abs(psi).max() < math.pi
    wrapped = three_axis.data.copy()
    wrapped["psi_rad"] = np.mod(psi, 2 * np.pi)
    from maneuvers.recording import Recording

    path = tmp_path / "wrapped.csv"
    write_recording(Recording(data=wrapped, meta=three_axis.meta, name="wrapped"), path)
    back = read_recording(path)
    assert np.allclose(np.unwrap(back.data["psi_rad"].to_numpy()), psi, atol=1e-12)


def test_condition_by_value():
    c = parse_condition("h=10000,V=427.4")
    assert (c.h_ft, c.V_fps, c.name) == (10_000.0, 427.4, "h=10000,V=427.4")
    assert condition_for("f16", "h=10000,V=427.4") == c
    assert condition_for("737", " V=700 , h=25000") .V_fps == 700.0
    for bad, words in (("h=10000", "V is missing"), ("h=1e4,V=abc", "must be a number"),
                       ("h=10000,V=427,x=1", "unknown or malformed"), ("h=10000,V=-5", "outside")):
        with pytest.raises(ValueError, match=words):
            parse_condition(bad)


@pytest.mark.parametrize("h_ft", [2_000.0, 16_000.0, 30_000.0])
def test_trim_anywhere_in_the_envelope(h_ft):
    """3 x 15 grid, 2,000-30,000 ft and 300-800 ft/s true airspeed: every point trims to an
    equilibrium; a point where the leading-edge flap's schedule leaves none holds it and says so."""
    aircraft = Aircraft("f16")
    for V in np.linspace(300.0, 800.0, 15):
        cond = FlightCondition("grid", h_ft, float(V))
        fdm = load_fdm(aircraft, 1 / 120)
        tp = trim(fdm, aircraft, cond)
        assert tp.V_fps == pytest.approx(V, rel=1e-9) and tp.h_ft == pytest.approx(h_ft, abs=1e-6)
        assert abs(fdm["accelerations/udot-ft_sec2"]) < 1e-3 and abs(fdm["accelerations/wdot-ft_sec2"]) < 1e-3
        assert abs(fdm["accelerations/qdot-rad_sec2"]) < 1e-4
        assert tp.configuration["positions"]["gear/gear-pos-norm"] == 0.0
        for surface, info in tp.held.items():
            assert tp.method == "surfaces" and info["held"] != info["scheduled"] and "hysteresis" in info["reason"]


def test_trim_holds_the_leading_edge_flap_at_its_switch():
    """10,000 ft and 428.7 ft/s: with the flap deployed the trim alpha is below its switch,
    retracted above it; trim holds it deployed and says so (and flies)."""
    rec = fly_maneuver(FlightSpec(condition="h=10000,V=428.7", duration_s=8.0))
    held = rec.meta["simulation"]["trim_held"]["fcs/lef-pos-rad"]
    assert held["held"] == 0.262 and held["scheduled"] == 0.0
    assert held["alpha_rad"] < 0.0873
    assert rec.meta["trim"]["alpha_rad"] == pytest.approx(held["alpha_rad"])
    q = rec.data["q_rps"].to_numpy()
    assert abs(q[0]) < 1e-9 and np.all(np.isfinite(q))


def test_no_equilibrium_names_the_condition_and_why():
    aircraft = Aircraft("f16")
    with pytest.raises(TrimError, match=r"cannot trim at .*h = 30000 ft, V = 200\.0 ft/s.*thrust"):
        trim(load_fdm(aircraft, 1 / 120), aircraft, FlightCondition("slow", 30_000.0, 200.0))


def test_accelerations_that_are_not_numbers_fail_the_trim_by_name(monkeypatch):
    """models.trim._solve_level: a model whose accelerations are not finite where the search
    starts (an augmented copy's added terms, say) fails its trim with a TrimError naming the
    condition and why, not scipy's ValueError (an internal error to the user)."""
    from models import trim as trim_module
    aircraft = Aircraft()
    fdm = load_fdm(aircraft, 1 / 120)
    fdm.run_ic()
    monkeypatch.setattr(trim_module, "_level_residual", lambda *args: [math.nan, 0.0, 0.0])
    with pytest.raises(TrimError, match="accelerations are not finite at alpha"):
        trim_module._solve_level(fdm, aircraft, condition_for("f16", None), {})


def test_737_flies_clean():
    aircraft = Aircraft("737")
    fdm = load_fdm(aircraft, 1 / 120)
    tp = trim(fdm, aircraft, condition_for("737"))
    assert tp.configuration["positions"]["gear/gear-pos-norm"] == 0.0
    assert fdm["aero/coefficient/CDgear"] == 0.0
    assert tp.configuration["positions"]["fcs/flap-pos-norm"] == 0.0


@pytest.mark.parametrize("name, condition", [("c182", "h=4000,V=180"), ("c310", "h=5000,V=200")])
def test_piston_engines_run_through_the_trim(name, condition):
    """JSBSim's run_ic leaves the c182's and c310's piston engines stopped even after
    ``propulsion/set-running``; the trim starts them again after run_ic, and finds level flight
    with thrust (before: "no level-flight equilibrium" at these cruise conditions)."""
    path = f"{jsbsim.get_default_root_dir()}/aircraft/{name}/{name}.xml"
    aircraft = Aircraft(path)
    fdm = load_fdm(aircraft, 1 / 120)
    tp = trim(fdm, aircraft, parse_condition(condition))
    engines = [i for i in range(4) if fdm.get_property_manager().hasNode(f"propulsion/engine[{i}]/thrust-lbs")]
    assert engines and all(fdm[f"propulsion/engine[{i}]/set-running"] == 1 for i in engines)
    assert sum(fdm[f"propulsion/engine[{i}]/thrust-lbs"] for i in engines) > 100.0
    assert tp.method == "jsbsim"
    assert abs(fdm["accelerations/udot-ft_sec2"]) < 1e-2 and abs(fdm["accelerations/wdot-ft_sec2"]) < 1e-2


@pytest.mark.parametrize("name, needle", [("fokker50", "/controls/engines/engine/throttle"),
                                          ("f104", "systems/radar/range")])
def test_a_package_aircraft_jsbsim_cannot_initialise_is_refused_by_name(name, needle):
    """The package's fokker50 and f104 read properties JSBSim alone does not define; their
    first run_ic fails inside JSBSim. Given by path, that is bad input (AircraftError, the CLI's
    exit 2 with one message), not an internal error."""
    from models.aircraft import AircraftError
    path = f"{jsbsim.get_default_root_dir()}/aircraft/{name}/{name}.xml"
    aircraft = Aircraft(path)
    with pytest.raises(AircraftError, match="JSBSim cannot initialise") as err:
        trim(load_fdm(aircraft, 1 / 120), aircraft, parse_condition("h=10000,V=350"))
    assert needle in str(err.value) and path in str(err.value)


def test_the_f16_fcs_laws_for_its_leading_edge_flap_and_flaperons():
    """models.configuration.f16_secondary_surfaces, pinned to f16.xml's switch and mixer: the
    flap at 0.262 rad above α = 0.0873, 0.436 above 0.2618, −0.0349 above Mach 0.9 below them;
    the flaperons' mix 1.4324 (clip(−tef − a) + clip(tef − a)), a = δa/0.375 · (1 − 0.85 M)."""
    from models.configuration import f16_secondary_surfaces as law
    assert law(0.05, 0.4, 300.0, 0.0) == {"fcs/lef-pos-rad": 0.0, "fcs/flaperon-mix-rad": 0.0}
    assert law(0.1, 0.4, 300.0, 0.0)["fcs/lef-pos-rad"] == 0.262
    assert law(0.3, 0.4, 300.0, 0.0)["fcs/lef-pos-rad"] == 0.436
    assert law(0.05, 0.95, 300.0, 0.0)["fcs/lef-pos-rad"] == -0.0349
    # half aileron at Mach 0, flaps up: a = 0.5, mix = 1.4324 (-0.5 - 0.5)
    assert law(0.0, 0.0, 300.0, 0.1875)["fcs/flaperon-mix-rad"] == pytest.approx(-1.4324)
    # the same below 250 kt: the trailing-edge flap (0.99981 normalised) clips one flaperon
    tef = 2.864789 * 0.349
    assert law(0.0, 0.0, 200.0, 0.1875)["fcs/flaperon-mix-rad"] == pytest.approx(1.4324 * (-1.0 + tef - 0.5))


def test_an_aircraft_whose_aerodynamics_read_normalised_surfaces_is_refused_by_name():
    """The package's T-38 reads fcs/elevator-pos-norm (its XML gives no radian scale): a
    recording's de_rad has nowhere to go, and the message says what the aerodynamics read."""
    from models.aircraft import AircraftError, library_xml, xml_surface_properties
    with pytest.raises(AircraftError, match=r"read fcs/elevator-pos-norm instead.*de input"):
        xml_surface_properties(str(library_xml("T38")))
    assert xml_surface_properties(str(library_xml("c172p")))["de"] == "fcs/elevator-pos-rad"


def test_a_recording_that_starts_banked_trims_the_model_in_that_steady_turn():
    """models.replay.InitialCondition: a record starting 45° banked is trimmed in JSBSim's
    steady coordinated turn there — bank 45°, load factor 1/cos 45° (its normal specific
    force), turn rate g·tan φ / V (ψ̇), and more thrust than wings level (308 lbf against 281) — so that a
    propeller's slipstream over the tail is the banked flight's; under 5° it stays wings level."""
    from models.replay import TURN_BANK_MIN_DEG, InitialCondition
    path = f"{jsbsim.get_default_root_dir()}/aircraft/c172x/c172x.xml"
    aircraft = Aircraft(path)
    turn = InitialCondition(5000.0, 185.0, phi_rad=math.radians(45.0))
    fdm = load_fdm(aircraft, 1 / 120)
    tp = trim(fdm, aircraft, turn.condition())
    assert tp.method == "jsbsim-turn" and math.degrees(tp.phi_rad) == pytest.approx(45.0, abs=0.1)
    n = -fdm["forces/fbz-total-lbs"] / (fdm["inertia/mass-slugs"] * 32.174)
    assert n == pytest.approx(1 / math.cos(math.radians(45.0)), rel=0.01)
    assert fdm["velocities/psidot-rad_sec"] == pytest.approx(fdm["accelerations/gravity-ft_sec2"] / 185.0, rel=0.02)
    level = trim(load_fdm(aircraft, 1 / 120), aircraft,
                 InitialCondition(5000.0, 185.0, phi_rad=math.radians(TURN_BANK_MIN_DEG / 2)).condition())
    assert level.method == "jsbsim" and abs(level.phi_rad) < 0.01 and tp.thrust_lbf > 1.05 * level.thrust_lbf


def test_an_altitude_under_sea_level_trims_in_the_air():
    """models.trim.set_initial_condition: an altitude standing in from the density can be under
    sea level, JSBSim's terrain; there the J-3 Cub's gear stood on the ground and neither
    JSBSim's trim nor the project's found an equilibrium (a probe's stand-in -2,780 ft). The
    terrain is lowered under the aircraft: it trims as JSBSim trims it at altitude, 1,000 ft up."""
    from pathlib import Path

    from models.trim import TERRAIN_CLEARANCE_FT
    xml = str(Path(jsbsim.get_default_root_dir()) / "aircraft" / "J3Cub" / "J3Cub.xml")
    aircraft = Aircraft(xml)
    fdm = load_fdm(aircraft, 1 / 120)
    tp = trim(fdm, aircraft, FlightCondition("cold day", -2780.0, 97.5))
    assert tp.method == "jsbsim" and tp.h_ft == pytest.approx(-2780.0, abs=1.0)
    assert fdm["position/h-agl-ft"] == pytest.approx(TERRAIN_CLEARANCE_FT, abs=1.0)
    assert abs(fdm["accelerations/udot-ft_sec2"]) < 1e-3 and abs(fdm["accelerations/wdot-ft_sec2"]) < 1e-3
