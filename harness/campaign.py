"""Campaigns: a grid of flights × noise × methods × equations, N realizations per cell.

A campaign is a TOML file (see ``harness/campaigns/*.toml`` and the README). It expands into
:class:`Task` objects, one per (flight, noise, realization); each task runs every method and
equation of the grid on the same noisy recording, so methods are compared on identical data.
Seeds derive from the master seed and the identity of the flight, noise and realization
(never from order, worker count or executor), so results do not depend on how they are run.
"""
from __future__ import annotations

import difflib
import hashlib
import itertools
import json
import os
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path

from estimators.registry import COMBINED_METHODS, METHODS, method_info
from estimators.regressors import Equation
from harness.errors import UserError
from harness.noise import ChannelNoise, NoiseModel
from harness.noise_presets import PRESETS, preset
from models.atmosphere import Turbulence

BUILTIN_DIR = Path(__file__).resolve().parent / "campaigns"
APPLY_TO = ("both", "regressors", "outputs")


class CampaignError(UserError):
    """A campaign file that cannot be run; the message names the file and the key."""


# Every key a campaign file may use, per table; anything else is refused (a typo would
# otherwise silently run something else than what was asked for).
TOP_KEYS = ("name", "description", "seed", "realizations", "truth", "combine", "grid", "flight", "flights",
            "maneuvers", "noise", "method_options", "method_factories", "plugins", "report")
GRID_KEYS = ("aircraft", "variant", "condition", "maneuver", "loop", "noise", "method", "errors", "equations")
FLIGHT_DEFAULT_KEYS = ("duration_s", "sample_rate_hz")
FLIGHT_KEYS = ("aircraft", "variant", "condition", "maneuver", "loop", "duration_s")
NOISE_KEYS = ("preset", "scale", "apply_to", "output", "flight_scales")
PLUGIN_KEYS = ("allow",)
CAMPAIGN_VARIANTS = ("nominal", "exact-truth", "unstable", "linear")
PLUGINS_ENV = "SIDBENCH_PLUGINS"
"""Environment variable: a comma list of ``module:callable`` plug-ins allowed in ``[method_factories]``
(besides a campaign's own ``[plugins] allow = [...]``)."""


def _did_you_mean(word: str, known: tuple[str, ...]) -> str:
    close = difflib.get_close_matches(word, list(known), n=1)
    return f"; did you mean {close[0]!r}?" if close else ""


def _known_keys(table: object, known: tuple[str, ...], where: str, file: str) -> dict:
    """``table`` as a dict whose keys are all in ``known``; otherwise an error listing them."""
    if not isinstance(table, dict):
        raise CampaignError(f"{file}: {where} must be a table, not {_kind(table)}")
    for key in table:
        if key not in known:
            raise CampaignError(f"{file}: unknown key {where + '.' if where else ''}{key} (known: {', '.join(known)})"
                                + _did_you_mean(key, known))
    return table


def _kind(value: object) -> str:
    return {str: "text", bool: "true/false", int: "an integer", float: "a number", list: "a list",
            dict: "a table"}.get(type(value), type(value).__name__) + f" ({value!r})"


def _number(value: object, where: str, file: str, *, positive: bool = False) -> float:
    """A TOML integer or float (never text or true/false)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise CampaignError(f"{file}: {where} must be a number, not {_kind(value)}")
    if positive and not value > 0:
        raise CampaignError(f"{file}: {where} must be positive, not {value!r}")
    return float(value)


def _integer(value: object, where: str, file: str, *, minimum: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise CampaignError(f"{file}: {where} must be an integer, not {_kind(value)}")
    if minimum is not None and value < minimum:
        raise CampaignError(f"{file}: {where} must be at least {minimum}, not {value}")
    return value


def _text(value: object, where: str, file: str) -> str:
    if not isinstance(value, str):
        raise CampaignError(f"{file}: {where} must be text, not {_kind(value)}")
    return value


def _check_flight_axes(aircraft: str, variant: str, condition: str, loop: str, where: str, file: str) -> None:
    """Refuse an unknown aircraft, variant, condition or loop before anything is run or written."""
    from harness.flying import parse_loop
    from models.aircraft import MODELS
    from models.conditions import condition_for
    if aircraft not in MODELS:
        raise CampaignError(f"{file}: {where}aircraft {aircraft!r} is not one of {MODELS}"
                            + _did_you_mean(str(aircraft), MODELS))
    if variant not in CAMPAIGN_VARIANTS:
        raise CampaignError(f"{file}: {where}variant {variant!r} is not one of {CAMPAIGN_VARIANTS}"
                            + _did_you_mean(str(variant), CAMPAIGN_VARIANTS))
    try:
        condition_for(aircraft, condition)
        parse_loop(loop)
    except ValueError as exc:
        raise CampaignError(f"{file}: {where}{exc}") from None


def _allowed_plugins(d: dict, file: str) -> tuple[str, ...]:
    """Plug-ins (``module:callable``) the campaign file's ``[plugins] allow`` and the environment enable."""
    plugins = _known_keys(d.get("plugins", {}), PLUGIN_KEYS, "plugins", file)
    allow = plugins.get("allow", [])
    if not isinstance(allow, list) or not all(isinstance(x, str) for x in allow):
        raise CampaignError(f"{file}: plugins.allow must be a list of 'module:callable' texts")
    env = tuple(x.strip() for x in os.environ.get(PLUGINS_ENV, "").split(",") if x.strip())
    return tuple(allow) + env


def _method_factories(d: dict, methods: tuple[str, ...], file: str) -> tuple[tuple[str, str], ...]:
    """``[method_factories]``: only plug-ins explicitly enabled (they are code the run imports and calls)."""
    factories = d.get("method_factories", {})
    if not isinstance(factories, dict):
        raise CampaignError(f"{file}: method_factories must be a table")
    allowed = _allowed_plugins(d, file)
    for method, factory in factories.items():
        _text(factory, f"method_factories.{method}", file)
        if method not in methods:
            raise CampaignError(f"{file}: method_factories.{method}: the grid has no method {method!r} "
                                f"(methods: {', '.join(methods)})")
        if ":" not in factory:
            raise CampaignError(f"{file}: method_factories.{method} = {factory!r} must be 'module:callable'")
        if factory not in allowed:
            raise CampaignError(
                f"{file}: method_factories.{method} = {factory!r} is code this run would import and call; "
                f"enable it with [plugins] allow = [{factory!r}] in the campaign file or {PLUGINS_ENV}={factory} "
                "(only for files you trust)")
    return tuple(sorted(factories.items()))


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
    for x in v:
        if key != "loop" and not isinstance(x, str):
            raise CampaignError(f"{where}: grid.{key} entries must be text, not {_kind(x)}")
    return v


def load_campaign(path: str | Path) -> Campaign:
    """Parse a campaign TOML file (a path, or the name of a built-in campaign)."""
    p, text, d = _read_campaign_file(path)
    where = str(p)
    for key in ("name", "seed", "realizations", "grid"):
        if key not in d:
            raise CampaignError(f"{where}: missing key '{key}'")
    _known_keys(d, TOP_KEYS, "", where)
    grid = _known_keys(d["grid"], GRID_KEYS, "grid", where)
    flight_defaults = _known_keys(d.get("flight", {}), FLIGHT_DEFAULT_KEYS, "flight", where)
    name = _text(d["name"], "name", where)
    description = _text(d.get("description", ""), "description", where)
    seed = _integer(d["seed"], "seed", where, minimum=0)
    realizations = _integer(d["realizations"], "realizations", where, minimum=1)
    if not isinstance(d.get("combine", False), bool):
        raise CampaignError(f"{where}: combine must be true or false, not {_kind(d['combine'])}")
    truth = d.get("truth", "local")
    if truth not in ("local", "fit"):
        raise CampaignError(f"{where}: truth must be 'local' or 'fit', not {truth!r}")
    mdefs = {mname: _maneuver_def(mname, spec, where) for mname, spec in
             _known_keys(d.get("maneuvers", {}), tuple(d.get("maneuvers", {})), "maneuvers", where).items()}
    maneuvers = [mdefs.get(m) or ManeuverDef(m, m) for m in _list(grid, "maneuver", ["2-1-1-2"], where)]
    noises = _noises(d, grid, where)
    flights = _flights(d, grid, flight_defaults, mdefs, maneuvers, where)
    combine = bool(d.get("combine", False))
    methods = _methods(grid, combine, flights, where)
    errors = tuple(_list(grid, "errors", ["conventional"], where))
    for e in errors:
        if e not in ("conventional", "colored"):
            raise CampaignError(f"{where}: grid.errors {e!r} must be 'conventional' or 'colored'")
    try:
        equations = tuple(parse_equation(e) for e in _list(grid, "equations", ["Cm = alpha + qhat + de"], where))
    except ValueError as exc:
        raise CampaignError(f"{where}: {exc}") from None
    return Campaign(name=name, description=description, seed=seed,
                    realizations=realizations, truth=truth, flights=flights, noises=noises,
                    methods=methods, errors=errors, equations=equations, path=str(p),
                    text_hash=hashlib.sha256(text.encode()).hexdigest(), extra=d.get("report", {}),
                    method_options=_method_options(d, where), combine=combine,
                    method_factories=_method_factories(d, methods, where))


def _read_campaign_file(path: str | Path) -> tuple[Path, str, dict]:
    """The file (a path, or a built-in campaign's name), its text and its TOML tables."""
    p = Path(path)
    if not p.suffix and not p.exists():
        p = BUILTIN_DIR / f"{path}.toml"
    if not p.is_file():
        names = sorted(x.stem for x in BUILTIN_DIR.glob("*.toml"))
        raise CampaignError(f"no campaign file {path!s} (built-in campaigns: {', '.join(names)})")
    try:
        text = p.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise CampaignError(f"{p}: not valid UTF-8 (byte {exc.start}); save the file as UTF-8") from None
    try:
        return p, text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CampaignError(f"{p}: not valid TOML: {exc}") from None


def _noises(d: dict, grid: dict, where: str) -> tuple[NoiseDef, ...]:
    """``grid.noise``: each a ``[noise.NAME]`` table of the file or a preset."""
    ndefs = {nname: _noise_def(nname, spec, where) for nname, spec in d.get("noise", {}).items()}
    noises = []
    for n in _list(grid, "noise", ["none"], where):
        if n in ndefs:
            noises.append(ndefs[n])
        elif n in PRESETS:
            noises.append(NoiseDef(n, n))
        else:
            raise CampaignError(f"{where}: grid.noise {n!r} is neither a preset {PRESETS} nor a [noise.{n}] table")
    return tuple(noises)


def _flights(d: dict, grid: dict, flight_defaults: dict, mdefs: dict, maneuvers: list, where: str
             ) -> tuple[FlightKey, ...]:
    """The flights: the file's ``[[flights]]`` list, or the product of the grid's flight axes."""
    duration = flight_defaults.get("duration_s")
    if duration is not None:
        duration = _number(duration, "flight.duration_s", where, positive=True)
    rate = _number(flight_defaults.get("sample_rate_hz", 50.0), "flight.sample_rate_hz", where, positive=True)
    if "flights" in d:
        # An explicit list of flights replaces the product of the grid's flight axes.
        flights = []
        if not isinstance(d["flights"], list):
            raise CampaignError(f"{where}: flights must be a list of [[flights]] tables")
        for i, f in enumerate(d["flights"]):
            _known_keys(f, FLIGHT_KEYS, f"flights[{i}]", where)
            if "duration_s" in f:
                _number(f["duration_s"], f"flights[{i}].duration_s", where, positive=True)
            _check_flight_axes(_text(f.get("aircraft", "f16"), f"flights[{i}].aircraft", where),
                               _text(f.get("variant", "nominal"), f"flights[{i}].variant", where),
                               _text(f.get("condition", "seed-5deg"), f"flights[{i}].condition", where),
                               str(f.get("loop", "open")), f"flights[{i}].", where)
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
        for f in flights:
            _check_flight_axes(f.aircraft, f.variant, f.condition, f.loop, "grid.", where)
    for f in flights:
        _check_maneuver_kind(f.maneuver, where)
    return flights


def _methods(grid: dict, combine: bool, flights: tuple[FlightKey, ...], where: str) -> tuple[str, ...]:
    """``grid.method``: methods of the registry, multiple-maneuver ones in a combined campaign."""
    allowed = COMBINED_METHODS if combine else METHODS
    methods = tuple(_list(grid, "method", ["ee-concat" if combine else "ee-time"], where))
    for m in methods:
        if m not in allowed:
            raise CampaignError(f"{where}: grid.method {m!r} is not one of {allowed}"
                                + (" (a combined campaign)" if combine else ""))
    if combine and len(flights) < 2:
        raise CampaignError(f"{where}: combine = true needs at least two flights")
    return methods


def _method_options(d: dict, where: str) -> tuple[tuple[str, tuple], ...]:
    """``[method_options.METHOD]``: frequencies, detrend, max_lag, autocorrelation and hold of a method."""
    method_options = []
    if not isinstance(d.get("method_options", {}), dict):
        raise CampaignError(f"{where}: method_options must be a table of [method_options.METHOD] tables")
    for m, opts in d.get("method_options", {}).items():
        if not isinstance(opts, dict):
            raise CampaignError(f"{where}: method_options.{m} must be a table")
        if m not in METHODS + COMBINED_METHODS:
            raise CampaignError(f"{where}: method_options.{m}: unknown method")
        bad = set(opts) - {"frequencies", "detrend", "max_lag", "autocorrelation", "hold"}
        if bad:
            raise CampaignError(f"{where}: method_options.{m}: unknown option(s) {sorted(bad)} "
                                "(frequencies, detrend, max_lag, autocorrelation, hold)")
        _check_method_options(m, opts, where)
        method_options.append((m, tuple(sorted((k, tuple(v) if isinstance(v, list) else v)
                                               for k, v in opts.items()))))
    return tuple(method_options)


def _maneuver_def(name: str, spec: object, file: str) -> ManeuverDef:
    """``[maneuvers] NAME = {kind = ..., surface = ..., ...}``: keys of :func:`maneuvers.inputs.make_input`."""
    import inspect

    from maneuvers.inputs import make_input
    known = tuple(inspect.signature(make_input).parameters) + ("gap_s",)
    spec = dict(_known_keys(spec, known, f"maneuvers.{name}", file))
    kind = _text(spec.pop("kind", name), f"maneuvers.{name}.kind", file)
    base = {}
    for key in ("amplitude_deg", "unit_pulse_s"):
        if key in spec:
            base[key] = _number(spec.pop(key), f"maneuvers.{name}.{key}", file)
    if "surface" in spec:
        base["surface"] = _text(spec.pop("surface"), f"maneuvers.{name}.surface", file)
    for key, value in spec.items():
        if key != "phases":
            _number(value, f"maneuvers.{name}.{key}", file)
    return ManeuverDef(name, kind, **base, options=tuple(sorted(spec.items())))


def _check_maneuver_kind(m: ManeuverDef, file: str) -> None:
    from maneuvers.inputs import INPUT_KINDS
    kinds = tuple(INPUT_KINDS) + ("three-axis", "lateral")
    if m.kind.lower() not in kinds:
        raise CampaignError(f"{file}: maneuver {m.name!r}: kind {m.kind!r} is not one of {kinds} "
                            "(nor a table of [maneuvers])" + _did_you_mean(m.kind, kinds))


def _noise_def(name: str, spec: object, file: str) -> NoiseDef:
    """``[noise.NAME]``: a preset, scaled, applied to regressors, outputs or both, plus output noise."""
    if not isinstance(spec, dict):
        raise CampaignError(f"{file}: noise.{name} = {spec!r}: noise set-ups are tables [noise.NAME] with keys "
                            f"{', '.join(NOISE_KEYS)}" + _did_you_mean(name, NOISE_KEYS))
    spec = _known_keys(spec, NOISE_KEYS, f"noise.{name}", file)
    if spec.get("preset", "none") not in PRESETS:
        raise CampaignError(f"{file}: noise.{name}.preset must be one of {PRESETS}")
    if spec.get("apply_to", "both") not in APPLY_TO:
        raise CampaignError(f"{file}: noise.{name}.apply_to must be one of {APPLY_TO}")
    output = spec.get("output", {})
    if not isinstance(output, dict):
        raise CampaignError(f"{file}: noise.{name}.output must be a table like {{ Cm = 0.0005 }}")
    scales = spec.get("flight_scales", [])
    if not isinstance(scales, list):
        raise CampaignError(f"{file}: noise.{name}.flight_scales must be a list of numbers")
    return NoiseDef(name, spec.get("preset", "none"), _number(spec.get("scale", 1.0), f"noise.{name}.scale", file),
                    spec.get("apply_to", "both"),
                    tuple(sorted((k, _number(v, f"noise.{name}.output.{k}", file)) for k, v in output.items())),
                    tuple(_number(x, f"noise.{name}.flight_scales", file) for x in scales))


def _check_method_options(method: str, opts: dict, file: str) -> None:
    """Option values the estimator can use (parsed now, not in a worker mid-run)."""
    from estimators.methods import parse_frequencies
    where = f"method_options.{method}"
    if "frequencies" in opts:
        try:
            parse_frequencies(_text(opts["frequencies"], f"{where}.frequencies", file))
        except ValueError as exc:
            raise CampaignError(f"{file}: {where}.frequencies: {exc}") from None
    if "detrend" in opts and opts["detrend"] not in ("endpoints", "lstsq"):
        raise CampaignError(f"{file}: {where}.detrend must be 'endpoints' or 'lstsq', not {opts['detrend']!r}")
    if "max_lag" in opts:
        _integer(opts["max_lag"], f"{where}.max_lag", file, minimum=0)
    if "autocorrelation" in opts and (not method_info(method).supports("colored")
                                      or opts["autocorrelation"] not in ("sample", "ar")):
        raise CampaignError(f"{file}: {where}.autocorrelation: 'sample' or 'ar' (methods with colored errors "
                            f"only), not {opts['autocorrelation']!r}")
    if "hold" in opts and (method != "ee-freq" or not isinstance(opts["hold"], list)
                           or not all(isinstance(h, str) for h in opts["hold"])):
        raise CampaignError(f"{file}: {where}.hold: a list of regressor names (ee-freq only), "
                            f"not {opts['hold']!r}")
