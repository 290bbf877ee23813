"""Mass properties written into an aircraft's XML (e.g. a flight-test recording's loading).

JSBSim builds its mass and inertia from ``<mass_balance>`` (empty weight, its c.g. and its
inertia about that c.g., plus point masses) and from the fuel tanks. :func:`set_mass_properties`
rewrites that so JSBSim's ``inertia/mass-slugs`` and ``inertia/{ixx,iyy,izz,ixz}-slugs_ft2``
are exactly the given values: point masses are removed, the empty-weight c.g. is put where
the loaded c.g. was, the fuel tanks are moved onto it (the engines need fuel to run, and a tank
on the c.g. adds mass but no inertia and no c.g. shift), and the empty weight is the given
weight less the fuel. Fuel is frozen after trim (models.trim), so the mass stays put in flight.
"""
from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path

from models.aircraft import PACKAGE_NAMES, is_xml_model, model_xml, nominal_tree
from models.jsbsim_root import cached_root

# JSBSim's own conversion (FGJSBBase::slugtolb): weight in lbs = mass in slug * 32.174049.
# Not the project's G0_FPS2 (32.17404855643): with JSBSim's constant the mass it computes
# from the written weight is the requested one to the last bits.
SLUG_TO_LB = 32.174049

_LENGTH_IN = {"IN": 1.0, "FT": 12.0, "M": 39.37007874015748}
_WEIGHT_LB = {"LBS": 1.0, "KG": 2.20462262185}


@dataclass(frozen=True)
class MassProperties:
    """Mass and inertia about the c.g. in body axes, in the recording format's keys.

    ``Ixz_slugft2`` uses the seed's sign convention (Eqs. 3-5), as recordings and
    :class:`models.trim.TrimPoint` do; JSBSim's inertia matrix (``inertia/ixz-slugs_ft2``,
    and the XML's ``<ixz>`` with ``negated_crossproduct_inertia="true"``) holds its negative.
    """

    mass_slug: float
    Ix_slugft2: float
    Iy_slugft2: float
    Iz_slugft2: float
    Ixz_slugft2: float

    def __post_init__(self) -> None:
        for k, v in asdict(self).items():
            if not (isinstance(v, (int, float)) and v == v and abs(v) != float("inf")):
                raise ValueError(f"{k} must be a finite number, not {v!r}")
        if self.mass_slug <= 0 or min(self.Ix_slugft2, self.Iy_slugft2, self.Iz_slugft2) <= 0:
            raise ValueError("mass and moments of inertia must be positive")

    @classmethod
    def from_mapping(cls, m: Mapping[str, float]) -> MassProperties:
        """From a mapping with the five keys, e.g. ``Recording.mass_at(0)`` (extra keys ignored)."""
        return cls(**{k: float(m[k]) for k in cls.__dataclass_fields__})

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


def _unit(el: ET.Element, table: Mapping[str, float], default: str, what: str) -> float:
    unit = el.get("unit", default).strip().upper()
    if unit not in table:
        raise ValueError(f"unsupported {what} unit {unit!r} in <{el.tag}> (known: {sorted(table)})")
    return table[unit]


def _weight_lb(el: ET.Element | None) -> float:
    if el is None:
        return 0.0
    return float(el.text) * _unit(el, _WEIGHT_LB, "LBS", "weight")


def _location_in(parent: ET.Element, what: str) -> tuple[float, float, float]:
    loc = parent.find("location")
    if loc is None:
        raise ValueError(f"{what} has no <location>")
    f = _unit(loc, _LENGTH_IN, "IN", "length")
    return tuple(float(loc.find(a).text) * f for a in "xyz")  # type: ignore[return-value]


def _set_location(parent: ET.Element, xyz_in: tuple[float, float, float], name: str | None = None) -> None:
    loc = parent.find("location")
    if loc is None:
        loc = ET.SubElement(parent, "location")
    for child in list(loc):
        loc.remove(child)
    loc.attrib.clear()
    if name:
        loc.set("name", name)
    loc.set("unit", "IN")
    for a, v in zip("xyz", xyz_in):
        ET.SubElement(loc, a).text = repr(float(v))


def _tanks(root: ET.Element) -> list[ET.Element]:
    prop = root.find("propulsion")
    return [] if prop is None else prop.findall("tank")


def loaded_cg_in(tree: ET.ElementTree) -> tuple[float, float, float]:
    """The c.g. (structural frame, inches) JSBSim computes for the XML's own loading:
    empty weight at its c.g., point masses and tank contents, weighted by weight."""
    root = tree.getroot()
    mb = root.find("mass_balance")
    if mb is None:
        raise ValueError("the aircraft has no <mass_balance>")
    items = [(_weight_lb(mb.find("emptywt")), _location_in(mb, "<mass_balance>"))]
    for pm in mb.findall("pointmass"):
        items.append((_weight_lb(pm.find("weight")), _location_in(pm, f"point mass {pm.get('name')!r}")))
    for i, tank in enumerate(_tanks(root)):
        items.append((_weight_lb(tank.find("contents")), _location_in(tank, f"tank {i}")))
    total = sum(w for w, _ in items)
    return tuple(sum(w * xyz[k] for w, xyz in items) / total for k in range(3))  # type: ignore[return-value]


def set_mass_properties(tree: ET.ElementTree, mass: MassProperties, *,
                        cg_in: tuple[float, float, float] | None = None) -> ET.ElementTree:
    """A copy of ``tree`` whose loaded mass and inertia are exactly ``mass``.

    ``<mass_balance>`` becomes: the inertia of ``mass`` (``<ixz>`` = -``Ixz_slugft2``,
    ``negated_crossproduct_inertia="true"``, no ``<ixy>``/``<iyz>``), the c.g. at ``cg_in``
    (default: where the tree's own loading put it, :func:`loaded_cg_in`), no point masses,
    and an empty weight that with the fuel makes ``mass``. Fuel tanks keep their contents and
    are moved onto that c.g. (the engines need fuel; there a tank adds no inertia and does
    not move the c.g.). The input tree is not modified.

    Raises
    ------
    ValueError
        If the fuel alone weighs at least the requested weight, or a unit is unknown.
    """
    cg = loaded_cg_in(tree) if cg_in is None else tuple(float(v) for v in cg_in)
    out = copy.deepcopy(tree)
    root = out.getroot()
    mb = root.find("mass_balance")
    tanks = _tanks(root)
    for i, tank in enumerate(tanks):
        for tag in ("radius", "inner_radius", "grain_config"):
            if tank.find(tag) is not None:
                raise ValueError(f"tank {i} has <{tag}>: its own inertia is not supported")
    fuel_lb = sum(_weight_lb(t.find("contents")) for t in tanks)
    weight_lb = mass.mass_slug * SLUG_TO_LB
    if fuel_lb >= weight_lb:
        raise ValueError(f"the fuel on board ({fuel_lb:.1f} lb) is not less than the requested "
                         f"weight ({weight_lb:.1f} lb)")
    for tank in tanks:
        _set_location(tank, cg)

    for child in list(mb):
        mb.remove(child)
    mb.attrib.clear()
    mb.set("negated_crossproduct_inertia", "true")
    for tag, value in (("ixx", mass.Ix_slugft2), ("iyy", mass.Iy_slugft2), ("izz", mass.Iz_slugft2),
                       ("ixz", -mass.Ixz_slugft2)):
        ET.SubElement(mb, tag, unit="SLUG*FT2").text = repr(float(value))
    ET.SubElement(mb, "emptywt", unit="LBS").text = repr(weight_lb - fuel_lb)
    _set_location(mb, cg, name="CG")
    ET.indent(mb, space="  ", level=1)
    return out


def mass_root(model: str, mass: MassProperties, *,
              cg_in: tuple[float, float, float] | None = None) -> tuple[Path, str]:
    """A cached JSBSim root of ``model``'s nominal aircraft with ``mass``; ``(root, name)``.

    Load it with ``models.aircraft.load_fdm(Aircraft(model), dt, root=root, name=name)`` and
    trim with :func:`models.trim.trim` as usual. The folder is keyed by the XML's content, so
    each loading gets its own and repeated calls cost only the XML rewrite.
    """
    if model not in PACKAGE_NAMES and not is_xml_model(model):
        raise ValueError(f"unknown aircraft {model!r}; choose one of {tuple(PACKAGE_NAMES)} or an XML path")
    tree = set_mass_properties(nominal_tree(model), mass, cg_in=cg_in)
    name = f"{PACKAGE_NAMES.get(model) or Path(model).stem}-mass"
    return cached_root(name, tree, model_xml(model)), name
