"""A recording script of the kind someone else would write: jsbsim alone, no sidbench code.

Stock package aircraft, trimmed by JSBSim, FCS disabled; a multisine on one or three axes
(harmonics of 0.1 Hz, random phases, interleaved between axes) or doublets on each axis in
turn, passed through a second-order actuator (40 rad/s, ζ 0.7) whose output is written to
the surfaces and recorded; every property read after ``run()``; white noise and a
Gauss-Markov wander (τ 1 s) on the vanes, scaled by ``noise``; any output rate that divides
the simulation rate; SI-radian, degree or metric unit conventions (recording-format.md).
"""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

G0 = 32.174
ACTUATOR_RPS, ACTUATOR_ZETA = 40.0, 0.7
SURFACE_PROPERTIES = {"f16": ("fcs/elevator-pos-rad", "fcs/aileron-pos-rad", "fcs/rudder-pos-rad"),
                      "737": ("fcs/elevator-pos-rad", "fcs/left-aileron-pos-rad", "fcs/rudder-pos-rad"),
                      "c172x": ("fcs/elevator-pos-rad", "fcs/effective-aileron-pos", "fcs/rudder-pos-rad")}


# The pilot's commands an aircraft's FCS reads (JSBSim's convention), for flights with it on.
STICK_COMMANDS = {"de": "fcs/elevator-cmd-norm", "da": "fcs/aileron-cmd-norm", "dr": "fcs/rudder-cmd-norm"}


def inputs(kind: str, amplitude_rad: float, duration_s: float, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Surface commands (rad from trim) at 100 Hz: ``ms3``, ``ms_pitch``, ``ms_lat`` multisines
    from 1 to 21 s, or ``dbl3`` doublets at 1, 8 and 15 s."""
    t = np.arange(0.0, duration_s, 0.01)
    out = {s: np.zeros_like(t) for s in ("de", "da", "dr")}
    if kind.startswith("ms"):
        axes = {"ms3": ("de", "da", "dr"), "ms_pitch": ("de",), "ms_lat": ("da", "dr")}[kind]
        harmonics = np.arange(2, 2 + 8 * len(axes))
        window = ((t >= 1.0) & (t < 21.0)).astype(float)
        for j, s in enumerate(axes):
            ks = harmonics[j::len(axes)]
            u = sum(np.cos(2 * np.pi * k * 0.1 * t + ph) for k, ph in zip(ks, rng.uniform(0, 2 * np.pi, len(ks))))
            out[s] = amplitude_rad * u / np.max(np.abs(u)) * window
    else:
        for s, t0 in (("de", 1.0), ("da", 8.0), ("dr", 15.0)):
            out[s] = amplitude_rad * (((t >= t0) & (t < t0 + 1)).astype(float) - ((t >= t0 + 1) & (t < t0 + 2)))
    return out


def trimmed(model: str, h_ft: float, V_fps: float, sim_hz: float = 100.0, xml_placement: bool = True,
            root: str | None = None):
    """``model`` trimmed by JSBSim in level flight at ``h_ft`` and ``V_fps``, gear up (see :func:`fly`):
    a retractable gear is put up at once; a fixed gear stays where it is, its drag included."""
    import jsbsim
    xml = Path(root or jsbsim.get_default_root_dir()) / "aircraft" / model / f"{model}.xml"
    retractable = "<retractable>1</retractable>" in xml.read_text().replace(" ", "")
    fdm = jsbsim.FGFDMExec(root)
    fdm.set_debug_level(0)
    assert fdm.load_model(model)
    fdm.set_dt(1.0 / sim_hz)
    fdm["ic/h-sl-ft"], fdm["ic/vt-fps"] = h_ft, V_fps
    fdm["gear/gear-cmd-norm"] = 0.0
    fdm["fcs/mixture-cmd-norm"], fdm["propulsion/magneto_cmd"], fdm["propulsion/starter_cmd"] = 1.0, 3, 1
    fdm.run_ic()
    if not xml_placement:
        for ax in "xyz":
            fdm[f"metrics/aero-rp-{ax}-in"] = fdm[f"inertia/cg-{ax}-in"]
        fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    if retractable:
        fdm["gear/gear-pos-norm"] = 0.0
    fdm["fcs/throttle-cmd-norm"] = 0.7
    fdm.do_trim(1)
    return fdm


def fly(path: Path, model: str, h_ft: float, V_fps: float, seed: int, out_hz: float, kind: str,
        units: str = "si", noise: float = 1.0, duration_s: float = 28.0, amplitude_deg: float = 2.0,
        xml_placement: bool = True, root: str | None = None, stick: bool = False) -> Path:
    """Fly ``model`` and write ``path`` (CSV) beside its ``.meta.json``; the 737's aerodynamic
    reference point stays where its XML puts it unless ``xml_placement`` is False (then it is
    moved onto the c.g., as shared/jsbsim-notes.md suggests for exact truth); ``root`` is a
    JSBSim root folder holding a modified copy of the aircraft (default: the package's).
    ``stick``: fly with the aircraft's FCS on, the inputs (``amplitude_deg`` read as hundredths
    of full stick) written to its pilot commands and the surfaces it moves recorded, as a
    flight-test aircraft flies."""
    sim_hz = 200.0 if 100.0 % out_hz else 100.0
    fdm = trimmed(model, h_ft, V_fps, sim_hz, xml_placement, root)
    if not stick:
        fdm["simulation/models/FGFCS/enabled"] = 0
    recorded = dict(zip(("de", "da", "dr"), SURFACE_PROPERTIES[model]))
    props = STICK_COMMANDS if stick else recorded
    trim = {s: fdm[p] for s, p in props.items()}
    rng = np.random.default_rng(seed)
    command = inputs(kind, amplitude_deg / 100.0 if stick else math.radians(amplitude_deg), duration_s + 1.0, rng)
    state = {s: [0.0, 0.0] for s in props}
    h = 1.0 / sim_hz / 4
    mass, n_sub = fdm["inertia/mass-slugs"], int(round(sim_hz / out_hz))
    rows = []
    for k in range(int(round(duration_s * out_hz)) + 1):
        for _ in range(n_sub if k else 0):
            i = int(round(fdm.get_sim_time() * 100))
            for s, prop in props.items():
                x, v = state[s]
                for _ in range(4):  # the actuator, x'' = w²(u − x) − 2ζw x', in four sub-steps
                    v += h * (ACTUATOR_RPS ** 2 * (command[s][i] - x) - 2 * ACTUATOR_ZETA * ACTUATOR_RPS * v)
                    x += h * v
                state[s] = [x, v]
                fdm[prop] = trim[s] + x
            fdm.run()
        rows.append([k / out_hz, fdm["velocities/vt-fps"], fdm["aero/alpha-rad"], fdm["aero/beta-rad"],
                     *(fdm[f"velocities/{a}i-rad_sec"] for a in "pqr"),
                     fdm["attitude/phi-rad"], fdm["attitude/theta-rad"], fdm["attitude/psi-rad"],
                     *(fdm[f"forces/fb{a}-total-lbs"] / (mass * G0) for a in "xyz"),
                     *(fdm[recorded[s]] for s in ("de", "da", "dr")), fdm["aero/qbar-psf"], fdm["position/h-sl-ft"]])
    X = np.array(rows)
    deg = math.radians(1.0)
    sigma = np.array([0, 0.5, 0.1 * deg, 0.1 * deg] + [0.1 * deg] * 3 + [0.2 * deg] * 3 + [0.01] * 3
                     + [0.05 * deg] * 3 + [0.3, 5]) * noise
    X += rng.normal(size=X.shape) * sigma
    a = math.exp(-1.0 / out_hz)
    for j in (2, 3):
        wander = np.zeros(len(X))
        for i, e in enumerate(rng.normal(scale=noise * 0.1 * deg * math.sqrt(1 - a * a), size=len(X))[1:], 1):
            wander[i] = a * wander[i - 1] + e
        X[:, j] += wander
    cols = ["t_s", "V_fps", "alpha_rad", "beta_rad", "p_rps", "q_rps", "r_rps", "phi_rad", "theta_rad", "psi_rad",
            "ax_g", "ay_g", "az_g", "de_rad", "da_rad", "dr_rad", "qbar_psf", "h_ft"]
    if units in ("deg", "metric"):
        for j, c in enumerate(cols):
            q, u = c.split("_")
            if u in ("rad", "rps"):
                X[:, j] = np.degrees(X[:, j])
                cols[j] = q + ("_deg" if u == "rad" else "_dps")
    if units == "metric":
        X[:, 1] *= 0.3048
        X[:, 10:13] *= G0 * 0.3048
        X[:, 17] *= 0.3048
        cols[1], cols[17] = "V_mps", "h_m"
        cols[10:13] = ["ax_mps2", "ay_mps2", "az_mps2"]
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(cols)
        writer.writerows([[f"{v:.8g}" for v in row] for row in X])
    meta = {"format": "flight-recording/1", "aircraft": model, "maneuver": kind,
            "geometry": {"S_ft2": fdm["metrics/Sw-sqft"], "b_ft": fdm["metrics/bw-ft"],
                         "cbar_ft": fdm["metrics/cbarw-ft"]},
            "mass": {"mass_slug": mass, "Ix_slugft2": fdm["inertia/ixx-slugs_ft2"],
                     "Iy_slugft2": fdm["inertia/iyy-slugs_ft2"], "Iz_slugft2": fdm["inertia/izz-slugs_ft2"],
                     "Ixz_slugft2": -fdm["inertia/ixz-slugs_ft2"]}}
    path.with_suffix(".meta.json").write_text(json.dumps(meta))
    return path
