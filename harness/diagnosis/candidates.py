"""Aerodynamic and actuator effects: the coefficient mismatch regressed on a library of
physically named candidate terms, a delay scan per surface, and the accelerometer position.

The coefficient mismatch of axis C is ``ΔC = C_measured − C_model(measured states)``. Each
candidate column is named by the effect of ``../shared/effects.md`` it stands for; the
columns enter by :func:`estimators.colored_stepwise.colored_forward_selection`, so a term is
named only when its colored-residual t statistic clears ``T_IN`` and it removes a real share
of the mismatch.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from estimators.colored_stepwise import ColoredSelection, colored_fit, colored_forward_selection
from estimators.least_squares import SingularRegressorsError, partial_correlation
from harness.diagnosis.kinematics import inertial_alpha_change, kinematic_alpha_rate
from harness.diagnosis.prepare import Prepared, filtered_noise_std, interior_slice
from models.constants import SURFACES

T_IN = 5.0
# A sensor parameter at this |t| is suspected, below its entry t: it keeps the terms it would
# imitate from being named, and beside a rival the data still prefer it while the rival
# falls below this (sensor_rules.contested_parameters, offset_rival).
AMBIGUOUS_T = 2.5
MIN_GAIN = 0.05
LON = ("CX", "CZ", "Cm")
LAT = ("CY", "Cl", "Cn")
AXIS_NAME = {"CX": "lon", "CZ": "lon", "Cm": "pitch", "CY": "lat", "Cl": "roll", "Cn": "yaw"}
SURFACE_AXES = {"de": LON, "da": LAT, "dr": LAT}
DELAY_GRID_S = np.arange(0.0, 0.3001, 0.002)


@dataclass(frozen=True)
class Term:
    """One candidate column: which effect it stands for and how its coefficient becomes the
    effect's size (``size = scale · coefficient``)."""

    key: str          # unique within an axis, e.g. 'alphadot'
    effect: str
    parameter: str
    units: str
    column: np.ndarray
    scale: float = 1.0
    details: dict = field(default_factory=dict)
    sources: tuple[str, ...] = ()  # the states/surfaces the column is built on (all must be driven)


def _hat(p: Prepared, rate: str, length: float) -> np.ndarray:
    return p.smooth[rate] * length / (2.0 * p.smooth["V"])


def regressors(p: Prepared) -> dict[str, np.ndarray]:
    """Perturbations from the recording's start (rates normalised), the model's own terms."""
    geo = p.meta["geometry"]
    s, st = p.smooth, p.start
    out = {"alpha": s["alpha"] - st["alpha"], "qhat": _hat(p, "q", geo["cbar_ft"]),
           "beta": s["beta"] - st["beta"], "phat": _hat(p, "p", geo["b_ft"]), "rhat": _hat(p, "r", geo["b_ft"])}
    for sfc in SURFACES:
        if sfc in s:
            out[sfc] = s[sfc] - st[sfc]
    return out


# The channels the kinematic α̇ is built on (kinematics.kinematic_alpha_rate).
ALPHA_RATE_CHANNELS = ("V", "alpha", "beta", "p", "q", "r", "phi", "theta", "ax", "az")
# The axes measured with the accelerometers that α̇ is built on: their α̇ column is the α
# record's derivative instead, whose noise is not the measurement's own.
VANE_ALPHA_RATE_AXES = ("CX", "CZ")


def alpha_rate(p: Prepared, axis: str = "Cm") -> np.ndarray:
    """α̇ (rad/s) along the recording, for a term of ``axis`` or the model's α̇ terms: the
    kinematic one (:func:`kinematics.kinematic_alpha_rate`, from the gyros, accelerometers
    and attitude through the common filter), whose noise is a fraction of the differentiated
    vane's; on the force axes (:data:`VANE_ALPHA_RATE_AXES`) the α record's derivative."""
    if axis in VANE_ALPHA_RATE_AXES or not all(c in p.smooth for c in ALPHA_RATE_CHANNELS):
        return p.deriv["alpha"]
    return kinematic_alpha_rate(p.smooth)


def alphadot_column(p: Prepared, axis: str) -> np.ndarray:
    """The regressor of an unsteady α̇ term of ``axis``: α̇ c̄/2V (effects.md's
    unsteady_alphadot), α̇ from :func:`alpha_rate`."""
    return alpha_rate(p, axis) * p.meta["geometry"]["cbar_ft"] / (2.0 * p.smooth["V"])


def effective_derivatives(p: Prepared, axis: str, model: np.ndarray) -> dict[str, float]:
    """The model's own derivatives of ``axis`` over this maneuver: its coefficient along the
    recorded states regressed on the axis's own regressors (and a constant). Equal to the
    trim derivatives for a linear model; for a model whose derivatives vary with the state
    (a C_n,β that changes with α, say) they are the values the maneuver actually saw, which
    the mismatch's changes are relative to."""
    reg = regressors(p)
    names = [r for r in (("alpha", "qhat", "de") if axis in LON else ("beta", "phat", "rhat", "da", "dr"))
             if r in reg and np.ptp(reg[r]) > 0]
    if not names:
        return {}
    inner = interior_slice(p.n, p.dt)
    A = np.column_stack([reg[r][inner] for r in names] + [np.ones(inner.stop - inner.start)])
    theta, *_ = np.linalg.lstsq(A, model[inner], rcond=None)
    inflation = variance_inflation(A)
    return {f"{axis}_{r}": float(v) for r, v, vif in zip(names, theta, inflation) if vif <= COLLINEAR_VIF}


def variance_inflation(A: np.ndarray) -> np.ndarray:
    """Each column's variance inflation factor in ``A`` (its last column the constant):
    1 / (1 − R²) of the column regressed on all the others, the factor by which collinearity
    inflates its coefficient's variance (infinite for a column the others reproduce)."""
    out = []
    for j in range(A.shape[1] - 1):
        x, others = A[:, j], np.delete(A, j, axis=1)
        fit, *_ = np.linalg.lstsq(others, x, rcond=None)
        residual = float(np.sum((x - others @ fit) ** 2))
        total = float(np.sum((x - np.mean(x)) ** 2))
        out.append(total / residual if residual > 0.0 else float("inf"))
    return np.array(out)


# A regressor whose variance inflation factor exceeds this (two columns correlated beyond
# 0.995) has no effective derivative of its own: the least-squares split between it and the
# columns that reproduce it is arbitrary (probe 66: a rudder geared to the aileron gave the
# c172x an "effective" C_n,δr of +0.048 where its trim derivative is −0.042, and a finding
# sized from it). It keeps its trim derivative.
COLLINEAR_VIF = 100.0


# The derivatives a coefficient error is offered on, per axis group (seed Eqs. 6-11).
OWN_REGRESSORS = {"lon": ("alpha", "qhat", "de"), "lat": ("beta", "phat", "rhat", "da", "dr")}


def library(p: Prepared, axis: str, derivatives: dict[str, float], measured: dict[str, np.ndarray],
            model: dict[str, np.ndarray] | None = None) -> list[Term]:
    """The candidate terms for the mismatch of coefficient ``axis``. With ``model`` (the
    model's coefficients along the recorded states) a coefficient error's model value is the
    model's effective derivative over the maneuver (:func:`effective_derivatives`), else its
    trim derivative."""
    geo = p.meta["geometry"]
    reg = regressors(p)
    a = reg["alpha"]
    units_of = {"qhat": "per rad (q normalised by c/2V)", "phat": "per rad (p normalised by b/2V)",
                "rhat": "per rad (r normalised by b/2V)"}
    own = OWN_REGRESSORS["lon" if axis in LON else "lat"]
    values = dict(derivatives)
    if model is not None:
        values.update(effective_derivatives(p, axis, model[axis]))
    terms = []
    for r in own:
        if r in reg:
            terms.append(Term(r, "coefficient_error", f"{axis}_{r}", units_of.get(r, "per rad"), reg[r],
                              details={"model_value": values.get(f"{axis}_{r}", float("nan")),
                                       "trim_value": derivatives.get(f"{axis}_{r}", float("nan"))},
                              sources=(REGRESSOR_SOURCE[r],)))
    if axis in LON:
        terms.append(Term("alphadot", "unsteady_alphadot", f"{axis}_alphadot", "per rad (alphadot c/2V)",
                          alphadot_column(p, axis), sources=("alpha",)))
        terms.append(Term("alpha2", "nonlinear_alpha", f"{axis}_alpha2", "per rad^2", a ** 2, sources=("alpha",)))
        terms.append(Term("alpha3", "nonlinear_alpha", f"{axis}_alpha3", "per rad^3", a ** 3, sources=("alpha",)))
    else:
        terms.append(Term("alpha_beta", "cross_coupling", f"{axis}_alpha_beta", "per rad^2", a * reg["beta"],
                          sources=("alpha", "beta")))
        # a response even in sideslip: wrong for a symmetric airframe, yet easy to tabulate (β
        # itself, not its change from the start: the kink is at zero sideslip)
        terms.append(Term("beta_abs", "cross_coupling", f"{axis}_beta_abs", "per rad", np.abs(p.smooth["beta"]),
                          sources=("beta",)))
    V0 = p.start["V"]
    # on a lateral axis the drift term also needs the lateral motion it would scale
    terms.append(Term("dV", "flight_condition_drift", f"{axis}_dV", "per unit dV/V", (p.smooth["V"] - V0) / V0,
                      sources=("V",) if axis in LON else ("V", "beta")))
    if axis == "Cm":
        terms.append(Term("cg", "cg_offset", "dx_moment_reference", "ft", measured["CZ"], scale=geo["cbar_ft"],
                          sources=("alpha",)))
    if axis == "Cn":
        terms.append(Term("cg", "cg_offset", "dx_moment_reference", "ft", measured["CY"], scale=-geo["b_ft"],
                          sources=("beta",)))
    return terms


# The recorded channel each of the model's own regressors is built on.
REGRESSOR_SOURCE = {"alpha": "alpha", "qhat": "q", "de": "de", "beta": "beta", "phat": "p", "rhat": "r",
                    "da": "da", "dr": "dr"}


def offered(p: Prepared, terms: list[Term]) -> tuple[list[Term], list[Term]]:
    """The terms whose every source the maneuver drove (:attr:`Prepared.driven`), and the
    others: a column built on a state the maneuver did not move is that state's noise, and
    its coefficient would only measure how the model's derivative passes the noise on. A
    product of two driven states is offered only when they also moved together
    (:func:`joint_excitation`); otherwise it is skipped with ``details['not_offered']``."""
    driven = set(p.driven)
    keep, skipped = [], []
    for t in terms:
        if not set(t.sources) <= driven:
            skipped.append(t)
        elif t.key == "alpha_beta" and (why := _not_together(p)):
            skipped.append(Term(t.key, t.effect, t.parameter, t.units, t.column, t.scale,
                                {**t.details, "not_offered": why}, t.sources))
        else:
            keep.append(t)
    return keep, skipped


# The product (α − α₀)(β − β₀), less what α and β themselves carry, must stand this many times
# above the noise it picks up from them to be offered (the driven-state rule's 5).
JOINT_SNR = 5.0


def joint_excitation(p: Prepared) -> float:
    """How far α and β moved *together*: the RMS of (α − α₀)(β − β₀) once its least-squares
    fit on 1, α and β is removed (what a coupling term adds beyond the model's own
    derivatives), over the noise the product picks up from its factors,
    √((σ_α·rms β)² + (σ_β·rms α)²) with each σ the white noise the common filter passes. A
    sequential three-axis maneuver (stabilator, then aileron, then rudder) gives 1.6-2.8; the
    outside sweep's c172x three-axis maneuvers, where its α follows the lateral motion, 9-10;
    the project's coupled maneuver 19."""
    reg = regressors(p)
    inner = interior_slice(p.n, p.dt)
    a, b = reg["alpha"][inner], reg["beta"][inner]
    product = a * b
    X = np.column_stack([np.ones_like(a), a, b])
    rest = product - X @ np.linalg.lstsq(X, product, rcond=None)[0]
    na = filtered_noise_std(p.noise_std.get("alpha", 0.0), p.weights)
    nb = filtered_noise_std(p.noise_std.get("beta", 0.0), p.weights)
    noise = float(np.hypot(na * np.sqrt(np.mean(b ** 2)), nb * np.sqrt(np.mean(a ** 2))))
    return float(np.sqrt(np.mean(rest ** 2))) / max(noise, 1e-300)


def _not_together(p: Prepared) -> str:
    """Why an α·β term is not offered ('' when it is)."""
    ratio = joint_excitation(p)
    if ratio >= JOINT_SNR:
        return ""
    return (f"α and β never moved together: their product, beyond what α and β themselves carry, stands "
            f"{ratio:.1f} times above the noise it picks up from them (needs {JOINT_SNR:g})")


def contribution_share(column: np.ndarray, coefficient: float, measured: np.ndarray) -> float:
    """A term's practical size: the RMS of what it adds to the coefficient (coefficient ×
    its column, about the mean) over the RMS excursion of the measured coefficient."""
    excursion = float(np.std(measured))
    return float(abs(coefficient) * np.std(column) / excursion) if excursion > 0 else 0.0


# The smallest share of the coefficient's excursion a term must explain to be a finding
# (its practical significance, whatever its t): noise-free recordings of the model itself
# give up to 0.017 (filtering and sample-timing artefacts, F-16 three-axis), the project's
# concealed effects 0.09-0.39 (gallery and sweep, realistic noise).
PRACTICAL_SHARE = 0.04


def share_below_practical(share: float) -> str:
    """"x % of the coefficient's excursion (under 4 %)" for a share under
    :data:`PRACTICAL_SHARE`, with as many decimals as it takes not to print the limit itself
    (3.96 % read "4.0 % (under 4 %)")."""
    limit = 100 * PRACTICAL_SHARE
    digits = next((d for d in (1, 2, 3) if round(100 * share, d) < limit), 4)
    return f"{100 * share:.{digits}f} % of the coefficient's excursion (under {limit:.0f} %)"


@dataclass(frozen=True)
class DelayScan:
    surface: str
    tau_s: float
    std_error: float
    t: float
    sse: np.ndarray      # normalised SSE over DELAY_GRID_S
    columns: dict[str, np.ndarray]  # per axis: ΔC(τ̂)/τ̂ (coefficient of the column is τ)


def _shift(x: np.ndarray, tau: float, dt: float) -> np.ndarray:
    t = np.arange(x.size) * dt
    return np.interp(t - tau, t, x)


def delay_scan(p: Prepared, surface: str, mismatch: dict[str, np.ndarray], derivatives: dict[str, float],
               noise: dict[str, float]) -> DelayScan | None:
    """Scan a transport delay τ of ``surface``: the model then sees δ(t − τ), so its
    coefficients change by C_δ·(δ(t − τ) − δ(t)); τ̂ minimises the noise-weighted mismatch
    over the axes the surface drives. Its standard error is the colored-residual one of
    the linearised column −C_δ δ̇(t − τ̂). A surface is scanned when it moved
    (``p.driven``: its filtered signal clear of the noise the filter passes, not only its
    samples 5 times their noise): a probe's F-16 (27,400 ft / 716 ft/s, a 1° stabilator sweep
    whose sensor noise was 0.2°) with a 96 ms stabilator delay had no scan of it (probe seed
    3637)."""
    if surface not in p.smooth or surface not in p.driven:
        return None
    axes = [c for c in SURFACE_AXES[surface] if abs(derivatives.get(f"{c}_{surface}", 0.0)) > 0]
    if not axes:
        return None
    x = p.smooth[surface]
    inner = interior_slice(p.n, p.dt)
    sse = []
    for tau in DELAY_GRID_S:
        dx = _shift(x, tau, p.dt) - x
        total = 0.0
        for c in axes:
            r = mismatch[c][inner] - derivatives[f"{c}_{surface}"] * dx[inner]
            total += float(np.sum((r - r.mean()) ** 2)) / noise[c] ** 2
        sse.append(total)
    sse = np.asarray(sse)
    j = int(np.argmin(sse))
    tau = float(DELAY_GRID_S[j])
    xd = p.differentiate(_shift(x, tau, p.dt))
    # stacked linearised fit for the standard error
    z, col, intercepts = [], [], []
    for i, c in enumerate(axes):
        w = 1.0 / noise[c]
        dx = _shift(x, tau, p.dt) - x
        z.append((mismatch[c][inner] - derivatives[f"{c}_{surface}"] * dx[inner]) * w)
        col.append(-derivatives[f"{c}_{surface}"] * xd[inner] * w)
        ind = np.zeros(len(axes))
        ind[i] = 1.0
        intercepts.append(np.tile(ind, (inner.stop - inner.start, 1)))
    Z, G, I = np.concatenate(z), np.concatenate(col), np.vstack(intercepts)
    theta, se, _ = colored_fit(Z, [G] + [I[:, i] for i in range(len(axes))],
                               ["dtau"] + [f"b{i}" for i in range(len(axes))], constant=False)
    tau_hat = tau + float(theta[0]) if tau > 0 else float(theta[0])
    std = float(se[0])
    columns = {}
    for c in axes:
        if tau_hat > 1e-4:
            columns[c] = derivatives[f"{c}_{surface}"] * (_shift(x, tau_hat, p.dt) - x) / tau_hat
        else:
            columns[c] = -derivatives[f"{c}_{surface}"] * p.deriv[surface]
    return DelayScan(surface, tau_hat, std, tau_hat / std if std > 0 else 0.0, sse, columns)


def accelerometer_columns(p: Prepared) -> dict[str, dict[str, np.ndarray]]:
    """ΔCX, ΔCY, ΔCZ per ft of accelerometer x, y, z position (the coefficient error a
    sensor at r makes: m[ω̇ × r + ω × (ω × r)]/(q̄S)). A rate the maneuver did not drive
    (not in ``p.driven``) enters at its mean, its derivative at zero: its record is its
    gyro's noise, and the noise's derivative in a column biases the position toward zero
    (errors in variables). A probe's F-15 (12,300 ft / 821 ft/s, pitch doublets at 25 Hz)
    with its accelerometer 9.7 ft ahead read 2.4 ± 0.5 ft, the yaw gyro's differentiated
    noise in C_Y's x·ṙ column outweighing C_Z's q̇·x (10.2 ft on C_Z alone), and a C_Z,α and
    C_Z,δe change were named in its place (probe seed 3753)."""
    s, d = p.smooth, p.deriv
    m, S = float(np.mean(p.mass["mass_slug"])), p.meta["geometry"]["S_ft2"]

    def rate(g: str) -> tuple[np.ndarray, np.ndarray]:
        if g in p.driven:
            return s[g], d[g]
        return np.full(p.n, float(np.mean(s[g]))), np.zeros(p.n)
    (p_, pd), (q_, qd), (r_, rd) = rate("p"), rate("q"), rate("r")
    w = np.stack([p_, q_, r_], axis=-1)
    wd = np.stack([pd, qd, rd], axis=-1)
    out = {}
    for i, a in enumerate("xyz"):
        r = np.zeros(3)
        r[i] = 1.0
        extra = (np.cross(wd, r) + np.cross(w, np.cross(w, r))) * m / (s["qbar"] * S)[:, None]
        if not any(g in p.driven for g in POSITION_RATES[a]):  # nothing but the means: not fitted
            extra = np.zeros_like(extra)
        out[a] = {"CX": extra[:, 0], "CY": extra[:, 1], "CZ": extra[:, 2]}
    return out


# The rates whose motion shows each component of the accelerometer's position (ω̇ × r):
# x through q̇ (a_z) and ṙ (a_y), y through ṗ and ṙ, z through ṗ and q̇. A component none of
# whose rates the maneuver drove is not fitted (its columns would be the means' products only).
POSITION_RATES = {"x": ("q", "r"), "y": ("p", "r"), "z": ("p", "q")}


@dataclass(frozen=True)
class OffsetTest:
    position_ft: tuple[float, float, float]
    std_error_ft: tuple[float, float, float]
    t: tuple[float, float, float]
    gain: float


FORCE_AXES = ("CX", "CY", "CZ")


def stacked_forces(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float]):
    """The force mismatches' interiors stacked and noise-weighted, the accelerometer
    position's columns stacked alike (per component), and an intercept per axis."""
    cols = accelerometer_columns(p)
    inner = interior_slice(p.n, p.dt)
    m = inner.stop - inner.start
    Z = np.concatenate([mismatch[c][inner] / noise[c] for c in FORCE_AXES])
    X = {a: np.concatenate([cols[a][c][inner] / noise[c] for c in FORCE_AXES]) for a in "xyz"}
    I = [np.concatenate([np.full(m, 1.0 if c == ci else 0.0) for c in FORCE_AXES]) for ci in FORCE_AXES]
    return Z, X, I


def accelerometer_offset(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float],
                         below_hz: float | None = None) -> OffsetTest:
    """Least squares of the stacked, noise-weighted force mismatches on the accelerometer
    position (with an intercept per axis), colored-residual standard errors; ``below_hz``:
    the mismatches and the columns alike low-passed there first (a fourth-order Butterworth
    run forward and back, each axis apart), which a rigid offset's linear relation survives."""
    Z, X, I = stacked_forces(p, mismatch, noise)
    X = [X[a] for a in "xyz"]
    if below_hz is not None:
        b, a = signal.butter(4, below_hz, fs=1.0 / p.dt)
        m = Z.size // len(FORCE_AXES)

        def low(v: np.ndarray) -> np.ndarray:
            return np.concatenate([signal.filtfilt(b, a, v[k * m:(k + 1) * m]) for k in range(len(FORCE_AXES))])
        Z, X = low(Z), [low(x) for x in X]
    keep = [i for i in range(3) if np.ptp(X[i]) > 1e-12]
    theta, se, resid = colored_fit(Z, [X[i] for i in keep] + I, [f"r{i}" for i in keep] + list(FORCE_AXES),
                                   constant=False)
    _, _, r0 = colored_fit(Z, I, list(FORCE_AXES), constant=False)
    pos, ses = [0.0, 0.0, 0.0], [np.inf, np.inf, np.inf]
    for j, i in enumerate(keep):
        pos[i], ses[i] = float(theta[j]), float(se[j])
    gain = 1.0 - float(resid @ resid) / float(r0 @ r0)
    return OffsetTest(tuple(pos), tuple(ses), tuple(pos[i] / ses[i] if np.isfinite(ses[i]) and ses[i] > 0 else 0.0
                                                 for i in range(3)), gain)


def axis_selection(p: Prepared, axis: str, mismatch: np.ndarray, terms: list[Term],
                   extra: dict[str, np.ndarray] | None = None,
                   forced: dict[str, np.ndarray] | None = None) -> ColoredSelection:
    """Forward selection of ``terms`` (plus ``extra`` columns, e.g. a delay) on the interior
    of one axis's mismatch; ``forced`` nuisance columns are in every fit."""
    inner = interior_slice(p.n, p.dt)
    cands = {t.key: t.column[inner] for t in terms}
    for key, col in (extra or {}).items():
        cands[key] = col[inner]
    nuisance = {key: col[inner] for key, col in (forced or {}).items() if np.ptp(col[inner]) > 0}
    return colored_forward_selection(mismatch[inner], cands, forced=nuisance, t_in=T_IN, min_gain=MIN_GAIN,
                                     max_terms=3)


# A stepwise term is named only if it also stands at the entry t with the residual's
# autocorrelation taken from an autoregressive model of it (``autocorrelation="ar"`` of
# :func:`estimators.colored.colored_residual_covariance`) rather than Eq. 39's sample
# estimates. The residual of a least-squares fit is orthogonal to its columns, so its sample
# spectrum is depleted exactly at the frequencies where a narrow-band column (a multisine's
# few lines) carries its power, and Eq. 40 then reads that column's error too small; the AR
# model's spectrum is smooth there. An independent script's c172x null (5,100 ft / 181 ft/s,
# three-axis multisine at 25 Hz, noise 1) had a C_Y,r̂ change of −0.094 named at t −6.0: over
# 24 noise draws of the same flight the estimate scattered 1.4 times its reported error, as the
# AR error is 1.44 times Eq. 39's there (t −4.2).
AR_ENTRY_T = T_IN


def autoregressive_t(mismatch: np.ndarray, sel: ColoredSelection, columns: dict[str, np.ndarray],
                     forced: dict[str, np.ndarray] | None, inner: slice) -> dict[str, float]:
    """Each selected term's t in the axis's final fit (its nuisance columns, the selected terms
    and a constant, over ``inner``) with the AR residual autocorrelation (:data:`AR_ENTRY_T`);
    empty when that fit fails."""
    if not sel.names:
        return {}
    nuisance = [col[inner] for col in (forced or {}).values() if np.ptp(col[inner]) > 0]
    names = [f"nuisance{i}" for i in range(len(nuisance))] + list(sel.names)
    try:
        theta, se, _ = colored_fit(mismatch[inner], nuisance + [columns[n][inner] for n in sel.names], names,
                                   autocorrelation="ar")
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return {}
    j = len(nuisance)
    return {n: float(theta[j + i] / se[j + i]) if se[j + i] > 0 else np.inf for i, n in enumerate(sel.names)}


@dataclass(frozen=True)
class OffsetRival:
    """A coefficient error the force mismatch cannot tell from the accelerometer's offset."""

    parameter: str        # e.g. CY_beta
    correlation: float    # partial, of its stacked column with the offset's component
    t_offset: float       # the offset component's t beside it
    t_rival: float        # its t beside the offset
    built_on: str = "the measured states"  # what its columns are built on (INERTIAL_ALPHA: the inertial α)


# Only derivatives whose stacked column is at least this correlated with the offset's
# component are tried beside it (the test needs collinearity; the others cost a fit each).
OFFSET_RIVAL_CORRELATION = 0.3


# The regressor key of the inertial α's change (kinematics.inertial_alpha_change) among the
# offset's rival columns, and the derivative it stands for.
INERTIAL_ALPHA = "alpha_inertial"


def offset_rival_columns(reg: dict[str, np.ndarray], inner: slice) -> list[tuple[tuple[str, str], ...]]:
    """The coefficient errors :func:`offset_rival` tries beside the accelerometer's position,
    as (force axis, regressor) columns: each force axis's own derivatives
    (:data:`OWN_REGRESSORS`) alone, and each longitudinal one on C_X and C_Z together, a
    change of lift (or drag) along it, which the body axes share by the angle of attack
    (C_X = C_L sin α − C_D cos α, C_Z = −C_L cos α − C_D sin α); where ``reg`` has the
    inertial α (:data:`INERTIAL_ALPHA`), C_Z,α and that pair on it too."""
    moved = [r for r in reg if np.ptp(reg[r][inner]) > 0]
    out = [((axis, r),) for axis in FORCE_AXES for r in OWN_REGRESSORS["lon" if axis in LON else "lat"]
           if r in moved]
    lon = [r for r in OWN_REGRESSORS["lon"] if r in moved] + [r for r in (INERTIAL_ALPHA,) if r in moved]
    return out + [(("CZ", r),) for r in (INERTIAL_ALPHA,) if r in moved] + [(("CX", r), ("CZ", r)) for r in lon]


def rival_parameter(axis: str, regressor: str) -> str:
    """The derivative a rival column (:func:`offset_rival_columns`) stands for: the inertial
    α's is the axis's α derivative."""
    return f"{axis}_{'alpha' if regressor == INERTIAL_ALPHA else regressor}"


def offset_rival(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float],
                 off: OffsetTest) -> OffsetRival | None:
    """The coefficient error (:func:`offset_rival_columns`) the force mismatch cannot tell
    from the accelerometer's position (:func:`accelerometer_offset`): fitted beside it, the
    position's strongest component falls below the entry t, unless it stays at
    :data:`AMBIGUOUS_T` while the error's columns fall below that (the data still prefer the
    position: the kinematic rivals' rule, ``sensor_rules.contested_parameters``); the one
    that takes most from the position. An accelerometer ahead of the c.g. adds x·ṙ/g to a_y,
    and on a lateral maneuver ṙ follows β and the rudder: a C_Y,β 0.3 more negative, flown
    into F-16 XML copies (5° lateral multisines), read as an accelerometer 2.2 ft aft at
    10,000 ft / 427 ft/s (t −8.0; beside C_Y,β −1.4, C_Y,β −7.2 beside it) and 2.9 ft aft at
    20,000 ft / 600 ft/s (t −10.5; −1.6 and −2.7). True offsets of 5 and 10 ft on the sweeps'
    pitch and three-axis maneuvers kept t 3.7-10 beside every derivative, none of which
    reached |t| 2.1 beside them. An independent script's F-16 with C_L,α 0.5 higher
    (7,300 ft / 482 ft/s, pitch 3-2-1-1 at 40 Hz) read as an accelerometer 10.9 ft aft
    (t −6.6): beside C_Z,α alone it stood at −5.2, beside C_X,α and C_Z,α together at −1.5
    (they at −11 and −17); on 36 probe recordings with the accelerometer 4 ft ahead it stayed
    at t 3.7-22 beside that pair. C_Z,α is also tried on the inertial α
    (:func:`kinematics.inertial_alpha_change`): an A-4 with C_Z,α 0.81 more negative (17,600 ft
    / 598 ft/s, a 0.7° pitch 3-2-1-1, its α vane's wander 0.17° against the maneuver's 0.29°)
    read as an accelerometer 10.4 ft aft (t −7.0), the clean q̇ of x·q̇ fitting what the noisy
    vane's α could not (t −6.0 beside C_Z,α on the vane, t −2.4 on the inertial α); the 17 probe
    recordings with the accelerometer 5-10 ft off kept the same t, or more, on the inertial α.
    None when there is no such error."""
    k = int(np.argmax(np.abs(off.t)))
    if not np.isfinite(off.std_error_ft[k]):
        return None
    Z, X, I = stacked_forces(p, mismatch, noise)
    inner = interior_slice(p.n, p.dt)
    m, axes = inner.stop - inner.start, FORCE_AXES
    keep = [a for a in "xyz" if np.ptp(X[a]) > 1e-12]
    name = "xyz"[k]
    others = [X[a] for a in keep if a != name] + I
    reg = regressors(p)
    inertial = inertial_alpha_change(p)
    if inertial is not None:
        reg = reg | {INERTIAL_ALPHA: inertial}
    best = None
    for pairs in offset_rival_columns(reg, inner):
        cols = [np.concatenate([reg[r][inner] / noise[c] if c == axis else np.zeros(m) for c in axes])
                for axis, r in pairs]
        corr = max((partial_correlation(X[name], col, others) for col in cols), key=abs)
        if abs(corr) < OFFSET_RIVAL_CORRELATION:
            continue
        try:
            theta, se, _ = colored_fit(Z, [X[a] for a in keep] + I + cols,
                                       keep + list(axes) + [f"rival{i}" for i in range(len(cols))], constant=False)
        except (SingularRegressorsError, np.linalg.LinAlgError):
            continue
        j, n = keep.index(name), len(cols)
        t_off = float(theta[j] / se[j])
        t_rival = max((float(v) for v in theta[-n:] / se[-n:]), key=abs)
        prefers_offset = abs(t_off) >= AMBIGUOUS_T and abs(t_rival) < AMBIGUOUS_T
        if abs(t_off) < T_IN and not prefers_offset and (best is None or abs(t_off) < abs(best.t_offset)):
            on = "the inertial α" if any(r == INERTIAL_ALPHA for _, r in pairs) else "the measured states"
            best = OffsetRival(" and ".join(rival_parameter(axis, r) for axis, r in pairs), corr, t_off, t_rival, on)
    return best
