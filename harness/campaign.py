"""Campaigns: a grid of flights × noise × methods × equations, N realizations per cell.

A campaign is a TOML file (see ``harness/campaigns/*.toml`` and the README). It expands into
:class:`Task` objects, one per (flight, noise, realization); each task runs every method and
equation of the grid on the same noisy recording, so methods are compared on identical data.
Seeds derive from the master seed and the identity of the flight, noise and realization
(never from order, worker count or executor), so results do not depend on how they are run.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path

from estimators.regressors import Equation
from harness.noise import ChannelNoise, NoiseModel
from harness.noise_presets import PRESETS, preset
from models.atmosphere import Turbulence

BUILTIN_DIR = Path(__file__).resolve().parent / "campaigns"
APPLY_TO = ("both", "regressors", "outputs")
# Methods of a combined (multiple-maneuver) campaign, seed §III.F.
COMBINED_METHODS = ("ee-concat", "ee-sequential", "ee-sequential-unequal", "ee-freq-combined")


class CampaignError(ValueError):
    """A campaign file that cannot be run; the message names the file and the key."""


@dataclass(frozen=True)
class ManeuverDef:
    """A named maneuver of the campaign (arguments of :func:`maneuvers.inputs.make_input`)."""

    name: str
    kind: str
    surface: str = "de"
    amplitude_deg: float = 1.0
    unit_pulse_s: float = 1.0
    options: tuple[tuple[str, float | str], ...] = ()

    def build(self):
        """The input signal. A comma list of surfaces for a single-surface kind plays the
        same input on each in turn, 1 s apart (e.g. ``da,dr``: aileron then rudder)."""
        from maneuvers.combine import Sequence
        from maneuvers.inputs import default_lateral_input, default_three_axis_input, make_input
        if self.kind == "three-axis":
            return default_three_axis_input()
        if self.kind == "lateral":
            return default_lateral_input()
        surfaces = [x.strip() for x in self.surface.split(",") if x.strip()]
        opts = dict(self.options)
        gap = float(opts.pop("gap_s", 1.0))
        if self.kind == "multisine" or len(surfaces) == 1:
            return make_input(self.kind, self.surface, self.amplitude_deg, self.unit_pulse_s, **opts)
        parts = tuple(make_input(self.kind, s, self.amplitude_deg, self.unit_pulse_s, **opts) for s in surfaces)
        return Sequence(parts, gap_s=gap, name=f"{self.name}")


@dataclass(frozen=True)
class NoiseDef:
    """A named noise set-up: a preset (optionally scaled), applied to regressors, outputs or
    both, plus white noise added directly to equation-error dependent variables."""

    name: str
    preset: str = "none"
    scale: float = 1.0
    apply_to: str = "both"
    output: tuple[tuple[str, float], ...] = ()
    flight_scales: tuple[float, ...] = ()

    def model(self, flight_index: int = 0) -> NoiseModel:
        """The noise model (for a combined task, scaled for the ``flight_index``-th maneuver)."""
        if self.flight_scales:
            k = self.flight_scales[flight_index % len(self.flight_scales)]
            return self._model().scaled(k) if k != 1.0 else self._model()
        return self._model()

    def _model(self) -> NoiseModel:
        base = preset(self.preset)
        m = base if self.scale == 1.0 else base.scaled(self.scale)
        out = {k: ChannelNoise(white_std=v) for k, v in self.output}
        return NoiseModel(self.name, m.channels, tuple(sorted(out.items())), m.turbulence, m.source, m.drop)

    @property
    def turbulence(self) -> Turbulence | None:
        return preset(self.preset).turbulence


@dataclass(frozen=True)
class FlightKey:
    """What defines one clean flight (its content hash keys the flight cache)."""

    aircraft: str
    variant: str
    condition: str
    maneuver: ManeuverDef
    loop: str
    duration_s: float | None
    sample_rate_hz: float

    def digest(self) -> str:
        return hashlib.sha256(json.dumps(asdict(self), sort_keys=True).encode()).hexdigest()[:16]

    def label(self) -> str:
        return f"{self.aircraft}/{self.variant}/{self.condition}/{self.maneuver.name}/{self.loop}"


@dataclass(frozen=True)
class Task:
    """One unit of work: a flight, a noise set-up and a realization number."""

    campaign: str
    flight: FlightKey
    noise: NoiseDef
    realization: int
    seed: tuple[int, ...]
    methods: tuple[str, ...]
    errors: tuple[str, ...]
    equations: tuple[Equation, ...]
    method_options: tuple[tuple[str, tuple[tuple[str, str | float | int], ...]], ...] = ()
    extra_flights: tuple[FlightKey, ...] = ()
    method_factories: tuple[tuple[str, str], ...] = ()

    @property
    def flights(self) -> tuple[FlightKey, ...]:
        """All flights of the task (several for a combined multiple-maneuver task)."""
        return (self.flight,) + self.extra_flights

    @property
    def task_id(self) -> str:
        ident = f"{'+'.join(f.digest() for f in self.flights)}|{self.noise.name}|{self.realization}"
        return hashlib.sha256(ident.encode()).hexdigest()[:20]


@dataclass(frozen=True)
class Campaign:
    """A parsed campaign file."""

    name: str
    description: str
    seed: int
    realizations: int
    truth: str
    flights: tuple[FlightKey, ...]
    noises: tuple[NoiseDef, ...]
    methods: tuple[str, ...]
    errors: tuple[str, ...]
    equations: tuple[Equation, ...]
    path: str = ""
    text_hash: str = ""
    extra: dict = field(default_factory=dict)
    method_options: tuple[tuple[str, tuple[tuple[str, str | float | int], ...]], ...] = ()
    combine: bool = False
    method_factories: tuple[tuple[str, str], ...] = ()

    def with_realizations(self, n: int) -> "Campaign":
        import dataclasses
        return dataclasses.replace(self, realizations=n)

    def tasks(self) -> list[Task]:
        out = []
        if self.combine:
            for noise in self.noises:
                for r in range(self.realizations):
                    out.append(Task(self.name, self.flights[0], noise, r,
                                    task_seed(self.seed, self.flights[0], noise, r), self.methods, self.errors,
                                    self.equations, self.method_options, self.flights[1:]))
            return out
        for flight, noise in itertools.product(self.flights, self.noises):
            for r in range(self.realizations):
                out.append(Task(self.name, flight, noise, r, task_seed(self.seed, flight, noise, r),
                                self.methods, self.errors, self.equations, self.method_options,
                                method_factories=self.method_factories))
        return out

    @property
    def cell_count(self) -> int:
        flights = 1 if self.combine else len(self.flights)
        return flights * len(self.noises) * len(self.methods) * len(self.errors) * len(self.equations)


def task_seed(master: int, flight: FlightKey, noise: NoiseDef, realization: int) -> tuple[int, ...]:
    """Seed words from the master seed and the identity of the flight, noise and realization."""
    ident = f"{flight.digest()}|{noise.name}|{realization}".encode()
    h = hashlib.sha256(ident).digest()
    return (int(master), int.from_bytes(h[:4], "little"), int.from_bytes(h[4:8], "little"), int(realization))


def parse_equation(text: str) -> Equation:
    """``'Cm = alpha + qhat + de'`` (a trailing ``- bias`` drops the bias term)."""
    if "=" not in text:
        raise CampaignError(f"equation {text!r} must look like 'Cm = alpha + qhat + de'")
    lhs, rhs = (s.strip() for s in text.split("=", 1))
    terms = [t.strip() for t in rhs.replace("-", "+-").split("+") if t.strip()]
    bias = "-bias" not in [t.replace(" ", "") for t in terms]
    terms = [t for t in terms if t.replace(" ", "") != "-bias"]
    return Equation(lhs, tuple(terms), bias)


def _list(d: dict, key: str, default: list, where: str) -> list:
    v = d.get(key, default)
    if not isinstance(v, list):
        v = [v]
    if not v:
        raise CampaignError(f"{where}: '{key}' is empty")
    return v


def load_campaign(path: str | Path) -> Campaign:
    """Parse a campaign TOML file (a path, or the name of a built-in campaign)."""
    p = Path(path)
    if not p.suffix and not p.exists():
        p = BUILTIN_DIR / f"{path}.toml"
    if not p.is_file():
        names = sorted(x.stem for x in BUILTIN_DIR.glob("*.toml"))
        raise CampaignError(f"no campaign file {path!s} (built-in campaigns: {', '.join(names)})")
    text = p.read_text()
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CampaignError(f"{p}: not valid TOML: {exc}") from None
    where = str(p)
    for key in ("name", "seed", "realizations", "grid"):
        if key not in d:
            raise CampaignError(f"{where}: missing key '{key}'")
    grid = d["grid"]
    flight_defaults = d.get("flight", {})
    truth = d.get("truth", "local")
    if truth not in ("local", "fit"):
        raise CampaignError(f"{where}: truth must be 'local' or 'fit', not {truth!r}")

    mdefs = {}
    for name, spec in d.get("maneuvers", {}).items():
        spec = dict(spec)
        kind = spec.pop("kind", name)
        base = {k: spec.pop(k) for k in ("surface", "amplitude_deg", "unit_pulse_s") if k in spec}
        mdefs[name] = ManeuverDef(name, kind, **base, options=tuple(sorted(spec.items())))
    maneuvers = [mdefs.get(m) or ManeuverDef(m, m) for m in _list(grid, "maneuver", ["2-1-1-2"], where)]

    ndefs = {}
    for name, spec in d.get("noise", {}).items():
        spec = dict(spec)
        if spec.get("preset", "none") not in PRESETS:
            raise CampaignError(f"{where}: noise.{name}.preset must be one of {PRESETS}")
        if spec.get("apply_to", "both") not in APPLY_TO:
            raise CampaignError(f"{where}: noise.{name}.apply_to must be one of {APPLY_TO}")
        ndefs[name] = NoiseDef(name, spec.get("preset", "none"), float(spec.get("scale", 1.0)),
                               spec.get("apply_to", "both"),
                               tuple(sorted((k, float(v)) for k, v in spec.get("output", {}).items())),
                               tuple(float(x) for x in spec.get("flight_scales", ())))
    noises = []
    for n in _list(grid, "noise", ["none"], where):
        if n in ndefs:
            noises.append(ndefs[n])
        elif n in PRESETS:
            noises.append(NoiseDef(n, n))
        else:
            raise CampaignError(f"{where}: grid.noise {n!r} is neither a preset {PRESETS} nor a [noise.{n}] table")

    duration = flight_defaults.get("duration_s")
    rate = float(flight_defaults.get("sample_rate_hz", 50.0))
    if "flights" in d:
        # An explicit list of flights replaces the product of the grid's flight axes.
        flights = []
        for i, f in enumerate(d["flights"]):
            m = f.get("maneuver", "2-1-1-2")
            flights.append(FlightKey(f.get("aircraft", "f16"), f.get("variant", "nominal"),
                                     f.get("condition", "seed-5deg"), mdefs.get(m) or ManeuverDef(m, m),
                                     str(f.get("loop", "open")), f.get("duration_s", duration), rate))
        flights = tuple(flights)
    else:
        flights = tuple(FlightKey(a, v, c, m, lp, duration, rate)
                        for a, v, c, m, lp in itertools.product(
                            _list(grid, "aircraft", ["f16"], where), _list(grid, "variant", ["nominal"], where),
                            _list(grid, "condition", ["seed-5deg"], where), maneuvers,
                            [str(x) for x in _list(grid, "loop", ["open"], where)]))
    from estimators.methods import METHODS
    combine = bool(d.get("combine", False))
    allowed = COMBINED_METHODS if combine else METHODS
    methods = tuple(_list(grid, "method", ["ee-concat" if combine else "ee-time"], where))
    for m in methods:
        if m not in allowed:
            raise CampaignError(f"{where}: grid.method {m!r} is not one of {allowed}"
                                + (" (a combined campaign)" if combine else ""))
    if combine and len(flights) < 2:
        raise CampaignError(f"{where}: combine = true needs at least two flights")
    errors = tuple(_list(grid, "errors", ["conventional"], where))
    for e in errors:
        if e not in ("conventional", "colored"):
            raise CampaignError(f"{where}: grid.errors {e!r} must be 'conventional' or 'colored'")
    try:
        equations = tuple(parse_equation(e) for e in _list(grid, "equations", ["Cm = alpha + qhat + de"], where))
    except ValueError as exc:
        raise CampaignError(f"{where}: {exc}") from None
    method_options = []
    for m, opts in d.get("method_options", {}).items():
        if m not in METHODS + COMBINED_METHODS:
            raise CampaignError(f"{where}: method_options.{m}: unknown method")
        bad = set(opts) - {"frequencies", "detrend", "max_lag"}
        if bad:
            raise CampaignError(f"{where}: method_options.{m}: unknown option(s) {sorted(bad)} "
                                "(frequencies, detrend, max_lag)")
        method_options.append((m, tuple(sorted(opts.items()))))
    return Campaign(name=d["name"], description=d.get("description", ""), seed=int(d["seed"]),
                    realizations=int(d["realizations"]), truth=truth, flights=flights, noises=tuple(noises),
                    methods=methods, errors=errors, equations=equations, path=str(p),
                    text_hash=hashlib.sha256(text.encode()).hexdigest(), extra=d.get("report", {}),
                    method_options=tuple(method_options), combine=combine,
                    method_factories=tuple(sorted(d.get("method_factories", {}).items())))
