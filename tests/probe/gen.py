#!/usr/bin/env python
"""Independent probe: draw one flight-test case from SEED and write OUTDIR/{id,val}.csv(+.meta.json), truth.json.

Uses jsbsim + numpy only.  Stock aircraft from the jsbsim package library, copied into a private
JSBSim root (input/output elements stripped, hidden physics appended), trimmed by JSBSim, flown
with the FCS disabled (surfaces written directly through a 2nd-order actuator whose output is
recorded), or for some F-16 cases with the FCS on through pilot commands.

gen.py also draws recording "conventions" (legal per recording-format.md, rarely produced by
a tool's own writer) from a separate generator default_rng([SEED, 7919]) -- see draw_conventions().
PROBE_OVERRIDE may hold "conventions": "all" (every option on, where applicable) or a list of option names.

usage: gen.py SEED OUTDIR
"""
from __future__ import annotations

import json
import math
import os
import shutil
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

G0 = 32.174
DEG = math.pi / 180.0
FT = 0.3048
KT = 1852.0 / 3600.0 / FT  # fps per knot
LBF_N = 4.4482216152605
PSF_PA = 47.880258980336

# name: (h range ft, V range fps, timescale factor for step inputs, retract gear)
ENVELOPES = {
    "f16": ((5000, 30000), (450, 720), 1.0),
    "737": ((10000, 30000), (450, 740), 1.6),
    "c172x": ((2000, 8000), (130, 185), 0.8),
    "c172r": ((2000, 8000), (130, 185), 0.8),
    "c172p": ((2000, 8000), (140, 185), 0.8),
    "c182": ((2000, 8000), (150, 200), 0.8),
    "F4N": ((10000, 30000), (520, 880), 1.0),
    "f15": ((10000, 30000), (520, 880), 1.0),
    "J3Cub": ((1000, 5000), (90, 118), 0.8),
    "T37": ((5000, 20000), (260, 450), 0.9),
    "A4": ((5000, 25000), (420, 740), 1.0),
    "787-8": ((15000, 32000), (520, 780), 1.6),
}
AILERON = {"f16": "fcs/aileron-pos-rad", "c172x": "fcs/effective-aileron-pos"}
STICK = {"de": "fcs/elevator-cmd-norm", "da": "fcs/aileron-cmd-norm", "dr": "fcs/rudder-cmd-norm"}

EFFECTS = {
    "coefficient_error": {"pitch": ["Cm_alpha", "Cm_qhat", "CZ_alpha"],
                          "lateral": ["Cl_beta", "Cn_beta", "Cl_phat", "Cn_rhat", "CY_beta"]},
    "unsteady_alphadot": {"pitch": ["Cm_alphadot"]},
    "nonlinear_alpha": {"pitch": ["Cm_alpha2", "Cm_alpha2", "CZ_alpha2"]},
    "cross_coupling": {"three_axis": ["Cl_alpha_beta", "Cn_alpha_beta"]},
    "control_delay": {"pitch": ["tau_de"], "lateral": ["tau_da", "tau_dr"]},
    "cg_offset": {"pitch": ["dx_moment_reference"]},
    "sensor_bias": {"any": ["bias_alpha", "bias_q", "bias_az", "bias_ax", "bias_V"],
                    "lateral": ["bias_beta", "bias_p", "bias_r", "bias_ay"]},
    "sensor_scale": {"pitch": ["scale_alpha"], "lateral": ["scale_beta"]},
    "sensor_offset": {"pitch": ["x_accelerometer"], "lateral": ["offset_y"]},
    "sensor_time_skew": {"pitch": ["skew_q", "skew_az", "skew_alpha"], "lateral": ["skew_p", "skew_r"]},
    "flight_condition_drift": {"pitch": ["Cm_dV"]},
    "turbulence": {"any": ["sigma_gust_fps"]},
    "structural_mode": {"any": ["mode_frequency_hz"]},
}
OVERRIDE = json.loads(os.environ.get("PROBE_OVERRIDE", "") or "{}")
CHANNEL = {"Cm": "q", "CZ": "az", "Cl": "p", "Cn": "r", "CY": "ay", "tau_de": "q", "tau_da": "p", "tau_dr": "r",
           "dx_moment_reference": "q", "x_accelerometer": "az", "offset_y": "ay", "offset_z": "ax",
           "mode_frequency_hz": "q", "sigma_gust_fps": ""}


class Skip(Exception):
    pass


# ----------------------------------------------------------------------------------------------- JSBSim root
def make_root(model: str, plant: dict | None) -> str:
    """A private JSBSim root holding a (possibly modified) copy of ``model``."""
    import jsbsim
    pkg = Path(jsbsim.get_default_root_dir())
    root = Path(tempfile.mkdtemp(prefix="root_", dir=os.getcwd()))
    (root / "aircraft").mkdir()
    for d in ("engine", "systems"):
        if (pkg / d).exists():
            os.symlink(pkg / d, root / d)
    dst = root / "aircraft" / model
    shutil.copytree(pkg / "aircraft" / model, dst)
    xml = dst / f"{model}.xml"
    tree = ET.parse(xml)
    top = tree.getroot()
    for child in list(top):  # sockets and output files of the shipped model
        if child.tag in ("input", "output"):
            top.remove(child)
    if plant:
        aero = top.find("aerodynamics")
        for axis_name, fn in plant.get("functions", []):
            ax = next((a for a in aero.findall("axis") if a.get("name") == axis_name), None)
            if ax is None:
                ax = ET.SubElement(aero, "axis", name=axis_name)
            ax.append(ET.fromstring(fn))
    tree.write(xml)
    return str(root)


def prop(p):
    return f"<property>{p}</property>"


def val(v):
    return f"<value>{float(v)!r}</value>"


def term_function(name, dim, gain, regressor_xml):
    """<function> giving qbar*S*[dim]*gain*regressor."""
    dims = [prop("aero/qbar-psf"), prop("metrics/Sw-sqft")] + ([prop(dim)] if dim else [])
    return (f'<function name="aero/probe/{name}"><description>probe</description><product>'
            + "".join(dims) + val(gain) + regressor_xml + "</product></function>")


def dalpha(a0):
    return f"<difference>{prop('aero/alpha-rad')}{val(a0)}</difference>"


# ----------------------------------------------------------------------------------------------- flying
def new_fdm(root, model, h, V, sim_hz, turb=None, aero_dx_in=0.0):
    import jsbsim
    xml = Path(root) / "aircraft" / model / f"{model}.xml"
    retract = "<retractable>1</retractable>" in xml.read_text().replace(" ", "")
    fdm = jsbsim.FGFDMExec(root)
    fdm.set_debug_level(0)
    if not fdm.load_model(model):
        raise Skip(f"load_model({model}) failed")
    fdm.set_dt(1.0 / sim_hz)
    fdm["ic/lat-geod-deg"], fdm["ic/long-gc-deg"] = 0.0, 0.0
    fdm["ic/h-sl-ft"] = h
    fdm["ic/vt-fps"] = V
    fdm["ic/psi-true-deg"] = 0.0
    fdm["gear/gear-cmd-norm"] = 0.0
    fdm["fcs/mixture-cmd-norm"], fdm["propulsion/magneto_cmd"], fdm["propulsion/starter_cmd"] = 1.0, 3, 1
    if aero_dx_in:
        fdm["metrics/aero-rp-x-in"] = fdm["metrics/aero-rp-x-in"] + aero_dx_in
    fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    if retract:
        fdm["gear/gear-pos-norm"] = 0.0
    fdm["fcs/throttle-cmd-norm"] = 0.7
    try:
        fdm.do_trim(1)
    except Exception as e:  # jsbsim.TrimFailureError
        raise Skip(f"trim failed: {model} h={h:.0f} ft V={V:.0f} fps ({type(e).__name__})")
    fdm["propulsion/fuel_freeze"] = 1
    if turb:
        fdm["atmosphere/randomseed"] = turb["seed"]
        fdm["atmosphere/turb-type"] = 3
        fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = turb["w20"]
        fdm["atmosphere/turbulence/milspec/severity"] = turb["severity"]
    return fdm


def surface_props(model):
    return {"de": "fcs/elevator-pos-rad", "da": AILERON.get(model, "fcs/left-aileron-pos-rad"),
            "dr": "fcs/rudder-pos-rad"}


def fly(root, model, h, V, sim_hz, cmd, stick=False, delay=None, turb=None, aero_dx_in=0.0,
        act=(40.0, 0.7)):
    """Fly the command histories ``cmd`` (dict surface -> array at sim rate, offsets from trim, rad or
    stick fraction). Returns dict of arrays at sim rate (sample 0 = trim)."""
    fdm = new_fdm(root, model, h, V, sim_hz, turb, aero_dx_in)
    surf = surface_props(model)
    if not stick:
        fdm["simulation/models/FGFCS/enabled"] = 0
    drive = STICK if stick else surf
    trim_in = {s: fdm[p] for s, p in drive.items()}
    n = len(next(iter(cmd.values())))
    dt = 1.0 / sim_hz
    wn, zeta = act
    nsub = 8
    hs = dt / nsub
    hist = {s: np.zeros(n) for s in drive}  # actuator output (pre-delay)
    mass = fdm["inertia/mass-slugs"]
    keys = ["V", "alpha", "beta", "p", "q", "r", "phi", "theta", "psi", "fx", "fy", "fz", "pdot", "qdot", "rdot",
            "de", "da", "dr", "qbar", "h", "mach", "thrust", "alphadot"]
    out = {k: np.zeros(n) for k in keys}

    node = fdm.get_property_manager().get_node  # property nodes: no path parsed per access
    reads = [("V", "velocities/vt-fps"), ("alpha", "aero/alpha-rad"), ("beta", "aero/beta-rad")]
    for a in "pqr":
        reads += [(a, f"velocities/{a}i-rad_sec"), (a + "dot", f"accelerations/{a}idot-rad_sec2")]
    reads += [("phi", "attitude/phi-rad"), ("theta", "attitude/theta-rad"), ("psi", "attitude/psi-rad")]
    getters = [(out[k], node(p).get_double_value) for k, p in reads]
    forces = [(out["f" + a], node(f"forces/fb{a}-total-lbs").get_double_value) for a in "xyz"]
    getters += [(out[k], node(p).get_double_value) for k, p in
                [("qbar", "aero/qbar-psf"), ("h", "position/h-sl-ft"), ("mach", "velocities/mach"),
                 ("thrust", "forces/fbx-prop-lbs"), ("alphadot", "aero/alphadot-rad_sec")]]
    surf_getters = [(out[s], node(surf[s]).get_double_value) for s in ("de", "da", "dr")] if stick else []
    setters = {s: node(p).set_double_value for s, p in drive.items()}
    right_aileron = node("fcs/right-aileron-pos-rad").set_double_value if (
        not stick and drive.get("da") == "fcs/left-aileron-pos-rad") else None
    mg = mass * G0

    def sample(i):
        for arr, get in getters:
            arr[i] = get()
        for arr, get in forces:
            arr[i] = get() / mg
        if stick:
            for arr, get in surf_getters:
                arr[i] = get()
        else:
            for s in ("de", "da", "dr"):
                out[s][i] = trim_in[s] + hist[s][i]

    # the actuators see only their commands: their outputs come first, step by step as flown
    w2, c2 = wn * wn, 2 * zeta * wn
    for s in drive:  # in Python floats (IEEE doubles, as NumPy's: the same numbers, faster)
        x, v = 0.0, 0.0
        c, h_s = cmd[s].tolist(), [0.0] * n
        for i in range(1, n):
            u = c[i - 1]
            for _ in range(nsub):
                v += hs * (w2 * (u - x) - c2 * v)
                x += hs * v
            h_s[i] = x
        hist[s][:] = h_s
    hist_list = {s: h.tolist() for s, h in hist.items()}
    run = fdm.run
    alpha, q, phi = out["alpha"], out["q"], out["phi"]
    sample(0)
    for i in range(1, n):
        for s in drive:
            applied = hist_list[s][i]
            if delay and s == delay[0]:
                tq = i - delay[1] * sim_hz
                if tq <= 0:
                    applied = 0.0
                else:
                    k = int(math.floor(tq))
                    f = tq - k
                    applied = hist[s][k] * (1 - f) + hist[s][min(k + 1, i)] * f
            setters[s](trim_in[s] + applied)
            if right_aileron is not None and s == "da":
                right_aileron(-(trim_in[s] + applied))
        run()
        sample(i)
        a = alpha[i]
        if not math.isfinite(a) or abs(a) > 30 * DEG or not math.isfinite(q[i]) or abs(phi[i]) > 80 * DEG:
            raise Skip(f"flight diverged at t={i * dt:.2f}s (alpha={a / DEG:.1f} deg, phi={phi[i] / DEG:.0f} deg)")
    out["trim"] = {"alpha": out["alpha"][0], "V": out["V"][0], "h": out["h"][0], "theta": out["theta"][0]}
    out["fdm"] = fdm
    return out


def stock_derivatives(root, model, h, V, sim_hz):
    """Rough stock derivatives about the c.g. by central differences with run_ic (for sizing only)."""
    fdm = new_fdm(root, model, h, V, sim_hz)
    fdm["simulation/models/FGFCS/enabled"] = 0
    S, b, c = fdm["metrics/Sw-sqft"], fdm["metrics/bw-ft"], fdm["metrics/cbarw-ft"]
    base = {k: fdm[f"ic/{k}"] for k in ("alpha-rad", "beta-rad", "p-rad_sec", "q-rad_sec", "r-rad_sec")}

    def coeffs(**kw):
        for k, v in base.items():
            fdm[f"ic/{k}"] = v
        for k, v in kw.items():
            fdm[f"ic/{k}"] = base[k] + v
        fdm.run_ic()
        qS = fdm["aero/qbar-psf"] * S
        return np.array([fdm["forces/fbz-aero-lbs"] / qS, fdm["forces/fby-aero-lbs"] / qS,
                         fdm["moments/l-aero-lbsft"] / (qS * b), fdm["moments/m-aero-lbsft"] / (qS * c),
                         fdm["moments/n-aero-lbsft"] / (qS * b)])

    d = {}
    da, dw = 0.2 * DEG, 0.5 * DEG
    ga = (coeffs(**{"alpha-rad": da}) - coeffs(**{"alpha-rad": -da})) / (2 * da)
    gb = (coeffs(**{"beta-rad": da}) - coeffs(**{"beta-rad": -da})) / (2 * da)
    gq = (coeffs(**{"q-rad_sec": dw}) - coeffs(**{"q-rad_sec": -dw})) / (2 * dw) * 2 * V / c
    gp = (coeffs(**{"p-rad_sec": dw}) - coeffs(**{"p-rad_sec": -dw})) / (2 * dw) * 2 * V / b
    gr = (coeffs(**{"r-rad_sec": dw}) - coeffs(**{"r-rad_sec": -dw})) / (2 * dw) * 2 * V / b
    d.update(CZ_alpha=ga[0], Cm_alpha=ga[3], CY_beta=gb[1], Cl_beta=gb[2], Cn_beta=gb[4], Cm_qhat=gq[3],
             Cl_phat=gp[2], Cn_rhat=gr[4])
    return {k: float(v) for k, v in d.items() if np.isfinite(v)}


# ----------------------------------------------------------------------------------------------- inputs
def step_sequence(pattern, dt_unit, t, t0):
    u = np.zeros_like(t)
    tt = t0
    for sign, units in pattern:
        u[(t >= tt) & (t < tt + units * dt_unit)] = sign
        tt += units * dt_unit
    return u, tt


PATTERNS = {"3-2-1-1": [(1, 3), (-1, 2), (1, 1), (-1, 1)], "2-1-1": [(1, 2), (-1, 1), (1, 1)],
            "doublet": [(1, 1), (-1, 1)]}


def design_input(rng, kind, style, t, T, tscale):
    """Unit-amplitude inputs per surface (dict), time t at sim rate, maneuver length T."""
    axes = {"pitch": ["de"], "lateral": ["da", "dr"], "three_axis": ["de", "da", "dr"]}[kind]
    u = {s: np.zeros_like(t) for s in ("de", "da", "dr")}
    t_start, t_end = 1.0, T - rng.uniform(3.0, 6.0)
    desc = []
    if style == "multisine":
        f0 = 1.0 / (t_end - t_start)
        fmax = rng.uniform(1.2, 2.0) / tscale
        ks = np.arange(max(1, int(0.1 / f0)), int(fmax / f0) + 1)
        rng.shuffle(ks) if rng.random() < 0.3 else None
        win = (t >= t_start) & (t < t_end)
        for j, s in enumerate(axes):
            kk = ks[j::len(axes)]
            ph = rng.uniform(0, 2 * np.pi, len(kk))
            x = sum(np.cos(2 * np.pi * k * f0 * (t - t_start) + p) for k, p in zip(kk, ph))
            x = x * win
            u[s] = x / max(np.max(np.abs(x)), 1e-9)
        desc.append(f"multisine {len(ks)} harmonics of {f0:.3f} Hz up to {fmax:.2f} Hz on {'+'.join(axes)}")
    elif style == "sweep":
        seg = (t_end - t_start) / len(axes)
        f1, f2 = rng.uniform(0.08, 0.2), rng.uniform(1.0, 2.0) / tscale
        for j, s in enumerate(axes):
            a, bnd = t_start + j * seg, t_start + (j + 1) * seg - 0.5
            m = (t >= a) & (t < bnd)
            tau = (t[m] - a) / (bnd - a)
            if rng.random() < 0.5:
                phase = 2 * np.pi * (bnd - a) * (f1 * tau + 0.5 * (f2 - f1) * tau ** 2)
            else:
                k = math.log(f2 / f1)
                phase = 2 * np.pi * (bnd - a) * f1 * (np.exp(k * tau) - 1) / k
            u[s][m] = np.sin(phase) * np.minimum(1.0, 4 * tau)
        desc.append(f"frequency sweep {f1:.2f}-{f2:.2f} Hz on {'+'.join(axes)} in turn")
    else:
        dt_unit = rng.uniform(0.35, 1.0) * tscale
        n_units = sum(k for _, k in PATTERNS[style])
        gap = (t_end - t_start) / len(axes)
        for j, s in enumerate(axes):
            du = dt_unit * (0.6 if s == "dr" else 1.0)
            du = min(du, 0.8 * gap / n_units)
            sgn = rng.choice([-1, 1])
            x, _ = step_sequence(PATTERNS[style], du, t, t_start + j * gap)
            u[s] = sgn * x
        desc.append(f"{style} on {'+'.join(axes)} in turn, unit {dt_unit:.2f} s")
    # lateral multi-axis with rudder: rudder amplitude relative to aileron
    return u, axes, "; ".join(desc)


# ----------------------------------------------------------------------------------------------- sensors
def shift(x, tau, dt):
    """x(t - tau) by linear interpolation (held at the first value before the start)."""
    t = np.arange(len(x)) * dt
    return np.interp(t - tau, t, x, left=x[0])


def structural(u, dt, f, zeta, rng):
    """Mode response eta (and eta') driven by u, second order, semi-implicit Euler sub-steps."""
    w = 2 * np.pi * f
    eta = np.zeros_like(u)
    x = v = 0.0
    nsub = 20
    h = dt / nsub
    du = np.gradient(u, dt)
    for i in range(1, len(u)):
        for _ in range(nsub):
            v += h * (w * w * (du[i - 1] / w - x) - 2 * zeta * w * v)
            x += h * v
        eta[i] = x
    return eta


# ----------------------------------------------------------------------------------------------- conventions
CONV_NAMES = ["angular_accel", "accel_position", "vanes", "mass_channels", "throttle", "time_offset", "shuffle",
              "extra_channel", "rare_units", "no_trim", "no_freetext"]
EXTRA = [("flap_deg", 0.0), ("trim_tab_rad", None), ("speedbrake_deg", 0.0), ("cabin_alt_ft", None),
         ("hyd_press_psf", None)]


def draw_conventions(seed, effect, param, with_thrust, with_h):
    """Options drawn from their own generator (every draw made unconditionally, so the stream is fixed)."""
    c = np.random.default_rng([seed, 7919])
    pr = {"angular_accel": 0.30, "accel_position": 0.25, "vanes": 0.25, "mass_channels": 0.20, "throttle": 0.20,
          "time_offset": 0.15, "shuffle": 0.15, "extra_channel": 0.10, "rare_units": 0.15, "no_trim": 0.10,
          "no_freetext": 0.10}
    on = {k: bool(c.random() < pr[k]) for k in CONV_NAMES}
    ov = OVERRIDE.get("conventions")
    if ov == "all":
        on = {k: True for k in CONV_NAMES}
    elif isinstance(ov, list):
        on = {k: k in ov for k in CONV_NAMES}
    sg = lambda: float(c.choice([-1.0, 1.0]))
    acc_pos = [sg() * float(c.uniform(2, 8)), float(c.uniform(-1, 1)), sg() * float(c.uniform(0.5, 3))]
    which_vanes = ["alpha", "beta", "both"][int(c.integers(3))]
    vane_a = [float(c.uniform(3, 15)), 0.0, float(c.uniform(-2, 2))]
    vane_b = [float(c.uniform(3, 15)), 0.0, float(c.uniform(-2, 2))]
    burn = 0.0 if c.random() < 0.5 else float(c.uniform(0.001, 0.005))
    t0 = [float(round(c.uniform(100, 50000), 2)) if c.random() < 0.75 else -float(round(c.uniform(1, 10), 2))
          for _ in range(2)]
    extra_i = int(c.integers(len(EXTRA)))
    extra_val = float(c.uniform(-3, 3))
    rare = {k: bool(c.random() < 0.6) for k in ("V_kts", "acc_fps2", "qbar_pa", "h_m", "thrust_n")}
    if not any(rare.values()):
        rare["thrust_n" if with_thrust else "V_kts"] = True
    file_seeds = [int(x) for x in c.integers(1 << 30, size=2)]
    # format: mass "may instead be given as channels" -- each key once (the tool refuses meta + channel)
    mass_keys = [["mass", "Ix", "Iy", "Iz", "Ixz"], ["mass"], ["Ix", "Iy", "Iz", "Ixz"]][int(c.choice(3, p=[.5, .25, .25]))]

    conv = {}
    if on["angular_accel"]:
        conv["angular_accel"] = True
    if on["accel_position"] and effect != "sensor_offset":
        conv["accel_position"] = acc_pos
    vane_fx = (effect in ("sensor_bias", "sensor_scale", "sensor_time_skew")
               and param.split("_", 1)[-1] in ("alpha", "beta"))
    if on["vanes"] and not vane_fx:
        v = {}
        if which_vanes in ("alpha", "both"):
            v["alpha"] = vane_a
        if which_vanes in ("beta", "both") or ov == "all":
            v["beta"] = vane_b
        conv["vanes"] = v
    if on["mass_channels"]:
        conv["mass_channels"] = {"burn_fraction": burn, "keys": mass_keys}
    if on["throttle"]:
        conv["throttle"] = True
    if on["time_offset"]:
        conv["time_offset"] = t0
    if on["shuffle"]:
        conv["shuffle"] = True
    if on["extra_channel"]:
        name, value = EXTRA[extra_i]
        if value is None:
            value = {"trim_tab_rad": extra_val * DEG, "cabin_alt_ft": 8000.0 + 100 * extra_val,
                     "hyd_press_psf": 432000.0 + 1000 * extra_val}[name]
        conv["extra_channel"] = [name, value]
    if on["rare_units"]:
        r = {k: True for k in rare} if ov == "all" else dict(rare)
        if not with_thrust:
            r["thrust_n"] = False
        if not with_h:
            r["h_m"] = False
        conv["rare_units"] = sorted(k for k, x in r.items() if x)
    if on["no_trim"]:
        conv["no_trim"] = True
    if on["no_freetext"]:
        conv["no_freetext"] = True
    conv["_file_seeds"] = file_seeds
    return conv


def conv_text(conv):
    parts = []
    for k, v in conv.items():
        if k.startswith("_"):
            continue
        if v is True:
            parts.append(k)
        elif k in ("accel_position",):
            parts.append(f"{k} [{', '.join(f'{x:.2f}' for x in v)}] ft")
        elif k == "vanes":
            parts.append("vanes " + ", ".join(f"{a}@[{', '.join(f'{x:.2f}' for x in r)}] ft" for a, r in v.items()))
        elif k == "mass_channels":
            parts.append(f"mass channels {'+'.join(v['keys'])} (burn {100 * v['burn_fraction']:.2f} %)")
        elif k == "time_offset":
            parts.append(f"t0 id {v[0]:g} s, val {v[1]:g} s")
        elif k == "extra_channel":
            parts.append(f"extra {v[0]}={v[1]:.6g}")
        elif k == "rare_units":
            parts.append("units " + "+".join(v))
    return "; ".join(parts) if parts else "none"


# ----------------------------------------------------------------------------------------------- main
def draw_case(seed):
    rng = np.random.default_rng(seed)
    model = list(ENVELOPES)[rng.integers(len(ENVELOPES))]
    (h0, h1), (v0, v1), tscale = ENVELOPES[model]
    h, V = float(rng.uniform(h0, h1)), float(rng.uniform(v0, v1))
    if rng.random() < 0.12:
        effect = "none"
    else:
        effect = list(EFFECTS)[rng.integers(len(EFFECTS))]
    kind = ["pitch", "lateral", "three_axis"][rng.integers(3)]
    param = ""
    if effect != "none":
        opts = EFFECTS[effect]
        if "three_axis" in opts:
            kind = "three_axis"
        pool = list(opts.get("any", []))
        if kind in ("pitch", "three_axis"):
            pool += opts.get("pitch", [])
        if kind in ("lateral", "three_axis"):
            pool += opts.get("lateral", [])
        if kind == "three_axis":
            pool += opts.get("three_axis", [])
        if not pool:  # effect needs the other axis
            kind = "pitch" if "pitch" in opts else "lateral"
            pool = list(opts.get("any", [])) + opts.get(kind, [])
        param = pool[rng.integers(len(pool))]
    ov = OVERRIDE
    if ov:  # for checks only: PROBE_OVERRIDE='{"model": "f16", "effect": "none", "noise": 0, ...}'
        model = ov.get("model", model)
        (h0, h1), (v0, v1), tscale = ENVELOPES[model]
        orng = np.random.default_rng([seed, 99])
        h, V = float(ov.get("h", orng.uniform(h0, h1))), float(ov.get("V", orng.uniform(v0, v1)))
        effect, param, kind = ov.get("effect", effect), ov.get("parameter", param), ov.get("kind", kind)
        if effect in ("none",):
            param = ""
    return rng, model, h, V, tscale, kind, effect, param


def main(seed: int, outdir: Path):
    outdir.mkdir(parents=True, exist_ok=True)
    rng, model, h, V, tscale, kind, effect, param = draw_case(seed)
    stick = model == "f16" and effect != "control_delay" and rng.random() < 0.15
    out_hz = float(rng.choice([25, 40, 50, 100, 200]))
    sim_hz = float(rng.choice([200, 400]))
    act = (float(rng.uniform(30, 60)), float(rng.uniform(0.6, 0.8)))
    noise = 0.0 if rng.random() < 0.08 else float(rng.uniform(0.3, 2.0))
    noise = float(OVERRIDE.get("noise", noise))
    stick = bool(OVERRIDE.get("stick", stick))
    units = ["canonical", "deg", "metric"][rng.integers(3)]
    with_h, with_mach, with_thrust = rng.random() < 0.75, rng.random() < 0.35, rng.random() < 0.3
    styles = ["multisine", "3-2-1-1", "2-1-1", "doublet", "sweep"]
    st_id = styles[rng.integers(5)]
    st_val = styles[rng.integers(5)]
    if effect == "cross_coupling":  # needs alpha and beta perturbed at the same time
        st_id = st_val = "multisine"
    T_id, T_val = float(rng.uniform(20, 40)), float(rng.uniform(20, 40))
    seeds_in = rng.integers(1 << 30, size=2)
    base = make_root(model, None)
    # targets for the excursions
    target = {"alpha": float(rng.uniform(1.2, 3.0)) * DEG, "beta": float(rng.uniform(1.5, 4.0)) * DEG,
              "phi": float(rng.uniform(15, 40)) * DEG}
    rdr = float(rng.uniform(0.3, 1.0))

    def maneuver(style, T, sd, root, delay=None, turb=None, dx_in=0.0, amps=None):
        r2 = np.random.default_rng(sd)
        t = np.arange(int(round(T * sim_hz)) + 1) / sim_hz
        u, axes, desc = design_input(r2, kind, style, t, T, tscale)
        if amps is None:  # pilot run at a nominal amplitude with the stock aircraft, scaled to the targets
            a0 = {"de": 1.0 * DEG, "da": 2.0 * DEG, "dr": 2.0 * DEG * rdr}
            if stick:
                a0 = {"de": 0.05, "da": 0.05, "dr": 0.05 * rdr}
            amps = dict(a0)
            for _ in range(2):
                cmd = {s: amps[s] * u[s] for s in ("de", "da", "dr")}
                try:
                    pr = fly(base, model, h, V, sim_hz, cmd, stick=stick, act=act)
                except Skip:
                    amps = {s: a * 0.3 for s, a in amps.items()}
                    continue
                da_ = np.max(np.abs(pr["alpha"] - pr["alpha"][0]))
                db_ = np.max(np.abs(pr["beta"]))
                dp_ = np.max(np.abs(pr["phi"]))
                if "de" in axes:
                    amps["de"] *= min(target["alpha"] / max(da_, 1e-4), 4.0)
                if "da" in axes:
                    f = min(target["beta"] / max(db_, 1e-4), target["phi"] / max(dp_, 1e-4), 4.0)
                    amps["da"] *= f
                    amps["dr"] *= f
            lim = {"de": 8 * DEG, "da": 12 * DEG, "dr": 12 * DEG} if not stick else {"de": 0.4, "da": 0.5, "dr": 0.5}
            amps = {s: min(a, lim[s]) for s, a in amps.items()}
            for _ in range(3):  # the stock flight at the final amplitude must stay in bounds
                cmd = {s: (amps[s] * u[s] if s in axes else 0 * u[s]) for s in ("de", "da", "dr")}
                try:
                    fly(base, model, h, V, sim_hz, cmd, stick=stick, act=act)
                    break
                except Skip:
                    amps = {s: a * 0.5 for s, a in amps.items()}
        cmd = {s: (amps[s] * u[s] if s in axes else 0 * u[s]) for s in ("de", "da", "dr")}
        rec = fly(root, model, h, V, sim_hz, cmd, stick=stick, delay=delay, turb=turb, aero_dx_in=dx_in, act=act)
        amp_txt = ", ".join(f"{s} {amps[s] / DEG:.2f} deg" if not stick else f"{s} {amps[s]:.3f} stick"
                            for s in axes)
        return rec, amps, f"{desc}; amplitude {amp_txt}; {T:.1f} s"

    # stock flights of both maneuvers first (sizes, trim, divergence check of the stock aircraft)
    try:
        stock_id, amps_id, desc_id = maneuver(st_id, T_id, seeds_in[0], base)
        stock_val, amps_val, desc_val = maneuver(st_val, T_val, seeds_in[1], base)
    except Skip as e:
        return skip(outdir, seed, str(e), model, h, V)
    a_trim, V_trim = stock_id["trim"]["alpha"], stock_id["trim"]["V"]
    try:
        der = stock_derivatives(base, model, h, V, sim_hz)
    except Skip as e:
        return skip(outdir, seed, str(e), model, h, V)

    def rms(x):
        return float(np.sqrt(np.mean(np.square(x))))

    dA = rms(stock_id["alpha"] - a_trim)
    dB = rms(stock_id["beta"])
    dVV = rms((stock_id["V"] - V_trim) / V_trim)
    dAmax = float(np.max(np.abs(stock_id["alpha"] - a_trim)))
    dAB = rms((stock_id["alpha"] - a_trim) * stock_id["beta"])
    erng_seed = int(rng.integers(1 << 30))

    def build(shrink):
        erng = np.random.default_rng(erng_seed)
        sgn = float(erng.choice([-1.0, 1.0]))
        truth, plant, delay, turb, dx_in, sensor = None, None, None, None, 0.0, None
        detail = ""
        floors = {"Cm_alpha": 0.2, "Cm_qhat": 5.0, "CZ_alpha": 2.0, "Cl_beta": 0.05, "Cn_beta": 0.05, "Cl_phat": 0.3,
                  "Cn_rhat": 0.15, "CY_beta": 0.3}
        stab = {"Cm_alpha": -1, "Cm_qhat": -1, "CZ_alpha": -1, "Cn_beta": 1, "Cl_beta": -1, "Cl_phat": -1, "Cn_rhat": -1,
                "CY_beta": -1}
        if effect == "coefficient_error":
            coef, reg = param.split("_")
            stock = der.get(param, float("nan"))
            ref = abs(stock) if np.isfinite(stock) and abs(stock) > 0.5 * floors[param] else floors[param]
            frac = float(erng.uniform(0.2, 0.6))
            if sgn != stab[param]:  # destabilising: smaller
                frac = float(erng.uniform(0.2, 0.4))
            truth = sgn * frac * ref * shrink
            regx = {"alpha": dalpha(a_trim), "beta": prop("aero/beta-rad"),
                    "qhat": prop("aero/ci2vel") + prop("velocities/q-aero-rad_sec"),
                    "phat": prop("aero/bi2vel") + prop("velocities/p-aero-rad_sec"),
                    "rhat": prop("aero/bi2vel") + prop("velocities/r-aero-rad_sec")}[reg]
            axis, dim, gain = {"Cm": ("PITCH", "metrics/cbarw-ft", truth), "Cl": ("ROLL", "metrics/bw-ft", truth),
                               "Cn": ("YAW", "metrics/bw-ft", truth), "CY": ("SIDE", None, truth),
                               "CZ": ("LIFT", None, -truth / math.cos(a_trim))}[coef]
            plant = {"functions": [(axis, term_function(param, dim, gain, regx))]}
            detail = f"stock {param} ~ {stock:+.4g}, added {truth:+.4g} ({100 * truth / stock if stock else 0:+.0f} %)"
        elif effect == "unsteady_alphadot":
            ref = max(abs(der.get("Cm_qhat", 0.0)), floors["Cm_qhat"])
            truth = -float(erng.uniform(0.3, 0.8)) * ref * (1 if erng.random() < 0.8 else -0.5) * shrink
            regx = prop("aero/ci2vel") + prop("aero/alphadot-rad_sec")
            plant = {"functions": [("PITCH", term_function(param, "metrics/cbarw-ft", truth, regx))]}
            detail = f"stock Cm_qhat ~ {der.get('Cm_qhat', float('nan')):+.4g}"
        elif effect == "nonlinear_alpha":
            coef = param.split("_")[0]
            ref = max(abs(der.get(f"{coef}_alpha", 0.0)), floors[f"{coef}_alpha"])
            truth = sgn * float(erng.uniform(0.15, 0.35)) * ref / max(dAmax, 0.5 * DEG) * shrink
            regx = dalpha(a_trim) + dalpha(a_trim)
            axis, dim, gain = ("PITCH", "metrics/cbarw-ft", truth) if coef == "Cm" else ("LIFT", None, -truth)
            plant = {"functions": [(axis, term_function(param, dim, gain, regx))]}
            detail = f"stock {coef}_alpha ~ {der.get(coef + '_alpha', float('nan')):+.4g}, max dalpha {dAmax / DEG:.2f} deg"
        elif effect == "cross_coupling":
            coef = param.split("_")[0]
            ref = max(abs(der.get(f"{coef}_beta", 0.0)), floors[f"{coef}_beta"])
            truth = sgn * float(erng.uniform(0.3, 0.6)) * ref * max(dB, 0.2 * DEG) / max(dAB, 1e-7) * shrink
            regx = dalpha(a_trim) + prop("aero/beta-rad")
            plant = {"functions": [({"Cl": "ROLL", "Cn": "YAW"}[coef], term_function(param, "metrics/bw-ft", truth, regx))]}
            detail = f"stock {coef}_beta ~ {der.get(coef + '_beta', float('nan')):+.4g}, rms dalpha*beta {dAB:.3g} rad^2"
        elif effect == "flight_condition_drift":
            ref = max(abs(der.get("Cm_alpha", 0.0)), floors["Cm_alpha"])
            truth = sgn * float(erng.uniform(0.3, 0.8)) * ref * max(dA, 0.3 * DEG) / max(dVV, 0.003)
            truth = float(np.clip(truth, -2.0, 2.0)) * shrink
            regx = f"<quotient><difference>{prop('velocities/vt-fps')}{val(V_trim)}</difference>{val(V_trim)}</quotient>"
            plant = {"functions": [("PITCH", term_function(param, "metrics/cbarw-ft", truth, regx))]}
            detail = f"rms dV/V {100 * dVV:.2f} %"
        elif effect == "cg_offset":
            ref = max(abs(der.get("Cm_alpha", 0.0)), floors["Cm_alpha"])
            cbar = stock_id["fdm"]["metrics/cbarw-ft"]
            czA = max(abs(der.get("CZ_alpha", 4.0)), 2.0)
            truth = sgn * float(erng.uniform(0.25, 0.6)) * ref * cbar / czA * shrink
            if sgn > 0:  # reference point (c.g.) forward = AERORP aft relative to it: stabilising; ok any size
                pass
            dx_in = 12.0 * truth  # convention: truth = Δ(aero-rp-x-in)/12 (AERORP moves aft = reference forward)
            detail = f"AERORP x {dx_in:+.2f} in (structural, aft +), cbar {cbar:.2f} ft, stock Cm_alpha ~ {der.get('Cm_alpha', float('nan')):+.4g}"
        elif effect == "control_delay":
            truth = float(erng.uniform(0.04, 0.12))
            delay = (param.split("_")[1], truth)
        elif effect == "turbulence":
            sev = int(erng.choice([3, 4]))
            w20 = float(erng.uniform(10, 20) if sev == 3 else erng.uniform(20, 35)) * 1.68781
            turb = {"seed": int(erng.integers(1, 10000)), "severity": sev, "w20": w20}
            detail = f"Milspec Dryden severity {sev} ({'light' if sev == 3 else 'moderate'}), W20 {w20:.1f} fps"
        elif effect == "sensor_bias":
            ch = param.split("_")[1]
            mag = {"alpha": (0.5, 2.0, DEG), "beta": (0.5, 2.0, DEG), "p": (0.3, 1.5, DEG), "q": (0.3, 1.5, DEG),
                   "r": (0.3, 1.5, DEG), "az": (0.01, 0.05, 1.0), "ay": (0.01, 0.05, 1.0), "ax": (0.01, 0.05, 1.0),
                   "V": (3.0, 15.0, 1.0)}[ch]
            truth = sgn * float(erng.uniform(mag[0], mag[1])) * mag[2]
            sensor = ("bias", ch, truth)
        elif effect == "sensor_scale":
            truth = sgn * float(erng.uniform(0.05, 0.15))
            sensor = ("scale", param.split("_")[1], truth)
        elif effect == "sensor_offset":
            truth = sgn * float(erng.uniform(3.0, 10.0))
            sensor = ("offset", param, truth)
        elif effect == "sensor_time_skew":
            truth = float(erng.uniform(0.03, 0.08))
            sensor = ("skew", param.split("_")[1], truth)
        elif effect == "structural_mode":
            truth = float(erng.uniform(3.0, 12.0))
            sensor = ("mode", param, truth, float(erng.uniform(0.02, 0.05)), float(erng.uniform(0.3, 1.0)) * DEG,
                      float(erng.uniform(0.015, 0.05)))
            detail = f"zeta {sensor[3]:.3f}, q rms {sensor[4] / DEG:.2f} deg/s, az rms {sensor[5]:.3f} g"

        if truth is not None and shrink != 1.0:
            detail += f"; size halved {int(round(math.log2(1 / shrink)))}x after divergence"
        return truth, plant, delay, turb, dx_in, sensor, detail

    # the recorded (planted) flights; an aerodynamic plant that makes the airframe diverge is halved (twice at most)
    aero = effect in ("coefficient_error", "unsteady_alphadot", "nonlinear_alpha", "cross_coupling",
                      "flight_condition_drift", "cg_offset")
    for attempt in range(3 if aero else 1):
        truth, plant, delay, turb, dx_in, sensor, detail = build(0.5 ** attempt)
        try:
            if plant or delay or turb or dx_in:
                root = make_root(model, plant) if plant else base
                rec_id, _, _ = maneuver(st_id, T_id, seeds_in[0], root, delay, turb, dx_in, amps_id)
                turb2 = dict(turb, seed=turb["seed"] + 1) if turb else None
                rec_val, _, _ = maneuver(st_val, T_val, seeds_in[1], root, delay, turb2, dx_in, amps_val)
            else:
                rec_id, rec_val = stock_id, stock_val
            break
        except Skip as e:
            if attempt == (2 if aero else 0):
                return skip(outdir, seed, f"{e} (effect {effect} {param})", model, h, V)

    nrng = np.random.default_rng(seed + 7919)
    spec = dict(units=units, with_h=with_h, with_mach=with_mach, with_thrust=with_thrust, noise=noise,
                out_hz=out_hz, sim_hz=sim_hz)
    conv = draw_conventions(seed, effect, param, with_thrust, with_h)
    for j, (name, rec, desc) in enumerate((("id", rec_id, desc_id), ("val", rec_val, desc_val))):
        write_recording(outdir / name, model, rec, desc, sensor, spec, nrng, stick, conv, j)

    channel = CHANNEL.get(param, "") if param in CHANNEL else ""
    if not channel and param:
        pre = param.split("_")[0]
        if pre in CHANNEL:
            channel = CHANNEL[pre]
        elif effect in ("sensor_bias", "sensor_scale", "sensor_time_skew"):
            channel = param.split("_", 1)[1]
    if effect == "turbulence":
        channel = ""
    descr = (f"seed {seed}: {model} h={h:.0f} ft V={V:.0f} fps (alpha_trim {a_trim / DEG:.2f} deg), {kind}, "
             f"{'FCS on (stick)' if stick else 'FCS off'}, id: {desc_id}; val: {desc_val}; effect {effect}"
             f"{' ' + param + '=' + format(truth, '.5g') if truth is not None else (' ' + param if param else '')}"
             f"{' (' + detail + ')' if detail else ''}; noise x{noise:.2f}, {units} units, {out_hz:.0f} Hz out, "
             f"sim {sim_hz:.0f} Hz, actuator {act[0]:.0f} rad/s zeta {act[1]:.2f}, h:{with_h} mach:{with_mach} "
             f"thrust:{with_thrust}; conventions: {conv_text(conv)}")
    tj = {"seed": seed, "aircraft": model, "h_ft": h, "V_fps": V, "kind": kind, "effect": effect,
          "parameter": param, "truth": truth, "channel": channel, "description": descr,
          "stock_derivatives": der, "fcs": "on" if stick else "off", "noise_factor": noise,
          "conventions": {k: v for k, v in conv.items() if not k.startswith("_")}}
    if OVERRIDE:
        tj["override"] = OVERRIDE
    (outdir / "truth.json").write_text(json.dumps(tj, indent=1))
    print(descr)


def write_recording(path: Path, model, rec, desc, sensor, spec, rng, stick, conv=None, fileno=0):
    sim_hz, out_hz = spec["sim_hz"], spec["out_hz"]
    dt = 1.0 / sim_hz
    ch = {k: rec[k].copy() for k in ("V", "alpha", "beta", "p", "q", "r", "phi", "theta", "psi", "de", "da", "dr",
                                     "qbar", "h", "mach", "thrust")}
    ch["ax"], ch["ay"], ch["az"] = rec["fx"].copy(), rec["fy"].copy(), rec["fz"].copy()
    conv = conv or {}
    crng = np.random.default_rng(conv.get("_file_seeds", [0, 0])[fileno])  # noise etc. of the added channels
    w_in = np.stack([rec["p"], rec["q"], rec["r"]], 1)  # inertial body rates
    wd_in = np.stack([rec["pdot"], rec["qdot"], rec["rdot"]], 1)
    if "accel_position" in conv:  # specific force AT the (known) accelerometer position
        rr = np.broadcast_to(np.array(conv["accel_position"], float), w_in.shape)
        extra = np.cross(wd_in, rr) + np.cross(w_in, np.cross(w_in, rr))
        ch["ax"] = ch["ax"] + extra[:, 0] / G0
        ch["ay"] = ch["ay"] + extra[:, 1] / G0
        ch["az"] = ch["az"] + extra[:, 2] / G0
    if "vanes" in conv:  # what a vane at r reads: air velocity there = V_air(body, c.g.) + omega x r
        Va, al, be = rec["V"], rec["alpha"], rec["beta"]
        uvw = np.stack([Va * np.cos(al) * np.cos(be), Va * np.sin(be), Va * np.sin(al) * np.cos(be)], 1)
        for which, r in conv["vanes"].items():
            rr = np.broadcast_to(np.array(r, float), w_in.shape)
            vv = uvw + np.cross(w_in, rr)
            if which == "alpha":
                ch["alpha"] = np.arctan2(vv[:, 2], vv[:, 0])
            else:
                ch["beta"] = np.arcsin(vv[:, 1] / np.linalg.norm(vv, axis=1))
    mode_q = None
    if sensor:
        kind, c = sensor[0], sensor[1]
        if kind == "bias":
            ch[c] = ch[c] + sensor[2]
        elif kind == "scale":
            ch[c] = (1 + sensor[2]) * ch[c]
        elif kind == "skew":
            ch[c] = shift(ch[c], sensor[2], dt)
        elif kind == "offset":
            r = {"x_accelerometer": (sensor[2], 0, 0), "offset_y": (0, sensor[2], 0),
                 "offset_z": (0, 0, sensor[2])}[c]
            w = np.stack([rec["p"], rec["q"], rec["r"]], 1)
            wd = np.stack([rec["pdot"], rec["qdot"], rec["rdot"]], 1)
            rr = np.broadcast_to(np.array(r, float), w.shape)
            extra = np.cross(wd, rr) + np.cross(w, np.cross(w, rr))
            ch["ax"] = ch["ax"] + extra[:, 0] / G0
            ch["ay"] = ch["ay"] + extra[:, 1] / G0
            ch["az"] = ch["az"] + extra[:, 2] / G0
        elif kind == "mode":
            _, _, f, zeta, q_rms, az_rms = sensor
            u = rec["de"] - rec["de"][0]
            if np.max(np.abs(u)) < 1e-6:
                u = rec["da"] - rec["da"][0]
            eta = structural(u, dt, f, zeta, None)
            s = max(np.sqrt(np.mean(eta ** 2)), 1e-12)
            ch["q"] = ch["q"] + q_rms * eta / s
            mode_q = q_rms * eta / s
            ch["az"] = ch["az"] - az_rms * eta / s
    step = int(round(sim_hz / out_hz))
    idx = np.arange(0, len(ch["V"]), step)
    n = len(idx)
    t = np.arange(n) / out_hz
    X = {k: v[idx] for k, v in ch.items()}
    if spec["noise"] > 0:
        nz = spec["noise"]
        sig = {"V": 0.5, "alpha": 0.1 * DEG, "beta": 0.1 * DEG, "p": 0.1 * DEG, "q": 0.1 * DEG, "r": 0.1 * DEG,
               "phi": 0.2 * DEG, "theta": 0.2 * DEG, "psi": 0.2 * DEG, "ax": 0.005, "ay": 0.005, "az": 0.01,
               "de": 0.05 * DEG, "da": 0.05 * DEG, "dr": 0.05 * DEG, "qbar": 0.3, "h": 5.0, "mach": 0.0005,
               "thrust": 20.0}
        for k in X:
            X[k] = X[k] + rng.normal(size=n) * sig[k] * nz
        a = math.exp(-1.0 / out_hz)  # Gauss-Markov, tau 1 s
        for k in ("alpha", "beta"):
            e = rng.normal(scale=nz * 0.1 * DEG * math.sqrt(1 - a * a), size=n)
            w = np.zeros(n)
            for i in range(1, n):
                w[i] = a * w[i - 1] + e[i]
            X[k] = X[k] + w
    # convention channels (decimated; noise from crng so the channels above are as gen.py makes them)
    fdm = rec["fdm"]
    E, E_unit = {}, {}
    if "angular_accel" in conv:
        for a, k in zip("pqr", range(3)):
            v = wd_in[:, k].copy()
            if a == "q" and mode_q is not None:  # the structural mode is a motion the sensor sees too
                v = v + np.gradient(mode_q, dt)
            E[a + "dot"] = v[idx] + crng.normal(size=n) * 0.5 * DEG * spec["noise"]
            E_unit[a + "dot"] = "rps2"
    if "mass_channels" in conv:
        tt = np.arange(n) / out_hz
        fac = 1.0 + conv["mass_channels"]["burn_fraction"] * (0.5 - tt / tt[-1])  # mean = simulated mass
        for k, pname, sgn in (("mass", "inertia/mass-slugs", 1), ("Ix", "inertia/ixx-slugs_ft2", 1),
                              ("Iy", "inertia/iyy-slugs_ft2", 1), ("Iz", "inertia/izz-slugs_ft2", 1),
                              ("Ixz", "inertia/ixz-slugs_ft2", -1)):
            if k not in conv["mass_channels"]["keys"]:
                continue
            E[k] = sgn * fdm[pname] * fac
            E_unit[k] = "slug" if k == "mass" else "slugft2"
    if "throttle" in conv:
        E["throttle"] = np.full(n, float(fdm["fcs/throttle-cmd-norm"]))
        E_unit["throttle"] = "1"
    if "extra_channel" in conv:
        nm, value = conv["extra_channel"]
        q_, u_ = nm.rsplit("_", 1)
        E[q_] = np.full(n, float(value))
        E_unit[q_] = u_
    moved = [s for s in ("de", "da", "dr") if np.ptp(ch[s]) > 1e-9]
    surf = [s for s in ("de", "da", "dr") if s in moved or rng.random() < 0.5] or ["de"]
    names = ["V", "alpha", "beta", "p", "q", "r", "phi", "theta", "psi", "ax", "ay", "az"] + surf + ["qbar"]
    if spec["with_h"]:
        names.append("h")
    if spec["with_mach"]:
        names.append("mach")
    if spec["with_thrust"]:
        names.append("thrust")
    canon = {"V": "fps", "alpha": "rad", "beta": "rad", "p": "rps", "q": "rps", "r": "rps", "phi": "rad",
             "theta": "rad", "psi": "rad", "ax": "g", "ay": "g", "az": "g", "de": "rad", "da": "rad", "dr": "rad",
             "qbar": "psf", "h": "ft", "mach": "1", "thrust": "lbf"}
    cols, data = ["t_s"], [t]
    for k in names:
        u, v = canon[k], X[k]
        if spec["units"] in ("deg", "metric") and u in ("rad", "rps"):
            v, u = np.degrees(v), ("deg" if u == "rad" else "dps")
        if spec["units"] == "metric":
            if u == "fps":
                v, u = v * FT, "mps"
            elif u == "g":
                v, u = v * G0 * FT, "mps2"
            elif u == "ft":
                v, u = v * FT, "m"
            elif u == "psf":
                v, u = v * 47.880258980336, "pa"
            elif u == "lbf":
                v, u = v * 4.4482216152605, "n"
        rare = conv.get("rare_units", [])
        if k == "V" and "V_kts" in rare:
            v, u = X[k] / KT, "kts"
        elif k in ("ax", "ay", "az") and "acc_fps2" in rare:
            v, u = X[k] * G0, "fps2"
        elif k == "qbar" and "qbar_pa" in rare:
            v, u = X[k] * PSF_PA, "pa"
        elif k == "h" and "h_m" in rare:
            v, u = X[k] * FT, "m"
        elif k == "thrust" and "thrust_n" in rare:
            v, u = X[k] * LBF_N, "n"
        cols.append(f"{k}_{u}")
        data.append(v)
    for k, v in E.items():
        u = E_unit[k]
        if u == "rps2" and spec["units"] in ("deg", "metric"):
            v, u = np.degrees(v), "dps2"
        cols.append(f"{k}_{u}")
        data.append(v)
    if "time_offset" in conv:
        data[0] = conv["time_offset"][fileno] + np.arange(n) / out_hz
    fmts = ["%.12g" if "time_offset" in conv else "%.8g"] + ["%.8g"] * (len(cols) - 1)
    if "shuffle" in conv:
        perm = crng.permutation(len(cols))
        cols, data, fmts = [cols[i] for i in perm], [data[i] for i in perm], [fmts[i] for i in perm]
    M = np.stack(data, 1)
    if not np.all(np.isfinite(M)):
        raise Skip("non-finite samples")
    with open(path.with_suffix(".csv"), "w") as fh:
        fh.write(",".join(cols) + "\n")
        for row in M:
            fh.write(",".join(f % x for f, x in zip(fmts, row)) + "\n")
    meta = {"format": "flight-recording/1", "aircraft": model,
            "geometry": {"S_ft2": fdm["metrics/Sw-sqft"], "b_ft": fdm["metrics/bw-ft"],
                         "cbar_ft": fdm["metrics/cbarw-ft"]},
            "mass": {"mass_slug": fdm["inertia/mass-slugs"], "Ix_slugft2": fdm["inertia/ixx-slugs_ft2"],
                     "Iy_slugft2": fdm["inertia/iyy-slugs_ft2"], "Iz_slugft2": fdm["inertia/izz-slugs_ft2"],
                     "Ixz_slugft2": -fdm["inertia/ixz-slugs_ft2"]},
            "sensors": {"accelerometer_ft": [float(x) for x in conv.get("accel_position", [0.0, 0.0, 0.0])]},
            "trim": {"alpha_rad": float(rec["trim"]["alpha"]), "V_fps": float(rec["trim"]["V"]),
                     "h_ft": float(rec["trim"]["h"])},
            "maneuver": desc + (" (FCS on, pilot stick inputs)" if stick else ""),
            "source": f"independent probe script, JSBSim {__import__('jsbsim').__version__} package model {model}, "
                      f"simulated at {sim_hz:.0f} Hz, recorded at {out_hz:.0f} Hz"}
    for which, r in conv.get("vanes", {}).items():
        meta["sensors"][f"{which}_vane_ft"] = [float(x) for x in r]
    if "mass_channels" in conv:
        for k in conv["mass_channels"]["keys"]:
            del meta["mass"][k + ("_slug" if k == "mass" else "_slugft2")]
        if not meta["mass"]:
            del meta["mass"]
    if "no_trim" in conv:
        del meta["trim"]
    if "no_freetext" in conv:
        del meta["maneuver"], meta["source"]
    path.with_suffix(".meta.json").write_text(json.dumps(meta, indent=1))


def skip(outdir, seed, reason, model, h, V):
    (outdir / "skip.json").write_text(json.dumps({"seed": seed, "aircraft": model, "h_ft": h, "V_fps": V,
                                                  "reason": reason}))
    print(f"seed {seed}: SKIP {reason}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    seed_, outdir_ = int(sys.argv[1]), Path(sys.argv[2]).resolve()
    workdir = tempfile.mkdtemp(prefix="probe_cwd_")
    os.chdir(workdir)  # any stray JSBSim output files land here
    try:
        sys.exit(main(seed_, outdir_) or 0)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
