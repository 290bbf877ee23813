"""Aircraft copies in a JSBSim root folder of their own.

JSBSim loads ``<root>/aircraft/<name>/<name>.xml`` and resolves engines and systems from
``<root>/engine`` and ``<root>/systems``. A modified aircraft (the 737 without its socket
input, the exact-truth F-16, a variant with hidden physics) is written into a fresh root
whose other folders link back to the package's own.
"""
from __future__ import annotations

import hashlib
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import jsbsim


def package_root() -> Path:
    """The JSBSim root shipped with the ``jsbsim`` package (aircraft, engine, systems)."""
    return Path(jsbsim.get_default_root_dir())


def aircraft_xml(model: str) -> ET.ElementTree:
    """Parse the package's XML for ``model`` (e.g. ``'f16'``, ``'737'``)."""
    path = package_root() / "aircraft" / model / f"{model}.xml"
    if not path.is_file():
        raise ValueError(f"JSBSim has no aircraft {model!r} (looked for {path})")
    return ET.parse(path)


def strip_io(tree: ET.ElementTree) -> ET.ElementTree:
    """Remove ``<input>`` (socket servers) and ``<output>`` elements, as the notes advise."""
    root = tree.getroot()
    for tag in ("input", "output"):
        for el in root.findall(tag):
            root.remove(el)
    return tree


def _link(src: Path, dst: Path) -> None:
    if not dst.exists() and not dst.is_symlink():
        dst.symlink_to(src, target_is_directory=src.is_dir())


def write_root(dest: Path, name: str, tree: ET.ElementTree, based_on: str) -> Path:
    """Write ``tree`` as aircraft ``name`` into JSBSim root ``dest`` and return ``dest``.

    The aircraft's sibling files (``Systems/``, init files) of the package's ``based_on``
    aircraft are linked beside it, and ``engine/`` and ``systems/`` at the root. The XML is
    written to a temporary file and renamed, so a reader never sees half of it.
    """
    pkg = package_root()
    craft_dir = dest / "aircraft" / name
    craft_dir.mkdir(parents=True, exist_ok=True)
    for sub in ("engine", "systems"):
        _link(pkg / sub, dest / sub)
    for item in (pkg / "aircraft" / based_on).iterdir():
        if item.name != f"{based_on}.xml":
            _link(item, craft_dir / item.name)
    target = craft_dir / f"{name}.xml"
    fd, tmp = tempfile.mkstemp(dir=craft_dir, suffix=".xml.tmp")
    with os.fdopen(fd, "wb") as fh:
        tree.write(fh, encoding="utf-8", xml_declaration=True)
    os.replace(tmp, target)
    return dest


def cached_root(name: str, tree: ET.ElementTree, based_on: str) -> Path:
    """A root for ``tree`` in the system temp folder, keyed by the XML's content hash.

    The same aircraft text always maps to the same folder, so processes share it and a
    second call costs nothing; nothing is held in memory between calls.
    """
    text = ET.tostring(tree.getroot())
    digest = hashlib.sha256(text + name.encode() + based_on.encode()).hexdigest()[:16]
    dest = Path(tempfile.gettempdir()) / "sidbench-aircraft" / f"{name}-{digest}"
    if not (dest / "aircraft" / name / f"{name}.xml").is_file():
        write_root(dest, name, tree, based_on)
    return dest
