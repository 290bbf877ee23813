"""Aircraft copies in a JSBSim root folder of their own.

JSBSim loads ``<root>/aircraft/<name>/<name>.xml`` and resolves engines and systems from
``<root>/engine`` and ``<root>/systems``. A modified aircraft (the 737 without its socket
input, the exact-truth F-16, a variant with hidden physics) is written into a fresh root
whose other folders link back to the package's own.
"""
from __future__ import annotations

import contextlib
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
    """Link ``dst`` to ``src`` unless it is there; processes writing the same root at once
    (a calibration's parallel flights) may both find it missing: the loser's link exists."""
    if not dst.exists() and not dst.is_symlink():
        with contextlib.suppress(FileExistsError):
            dst.symlink_to(src, target_is_directory=src.is_dir())


def engine_root(source: Path) -> Path:
    """The JSBSim root whose ``engine/`` and ``systems/`` an aircraft XML at ``source`` uses:
    its own root when it sits in one (``<root>/aircraft/<name>/<name>.xml`` beside
    ``<root>/engine``), otherwise the package's."""
    own = source.parent.parent.parent
    if source.parent.parent.name == "aircraft" and (own / "engine").is_dir():
        return own
    return package_root()


def write_root(dest: Path, name: str, tree: ET.ElementTree, source: Path) -> Path:
    """Write ``tree`` as aircraft ``name`` into JSBSim root ``dest`` and return ``dest``.

    ``source`` is the aircraft XML the tree was made from: its sibling files (``Systems/``,
    init files) are linked beside the copy, and ``engine/`` and ``systems/`` of its root
    (:func:`engine_root`) at the root. The XML is written to a temporary file and renamed,
    so a reader never sees half of it.
    """
    source = Path(source)
    craft_dir = dest / "aircraft" / name
    craft_dir.mkdir(parents=True, exist_ok=True)
    engines = engine_root(source)
    for sub in ("engine", "systems"):
        if (engines / sub).exists():
            _link(engines / sub, dest / sub)
    for item in source.parent.iterdir():
        if item.name not in (source.name, f"{name}.xml") and not item.name.endswith(".tmp"):
            _link(item, craft_dir / item.name)
    target = craft_dir / f"{name}.xml"
    fd, tmp = tempfile.mkstemp(dir=craft_dir, suffix=".xml.tmp")
    with os.fdopen(fd, "wb") as fh:
        tree.write(fh, encoding="utf-8", xml_declaration=True)
    os.replace(tmp, target)
    return dest


def cached_root(name: str, tree: ET.ElementTree, source: Path) -> Path:
    """A root for ``tree`` (made from the aircraft XML ``source``) in the system temp
    folder, keyed by the XML's content hash.

    The same aircraft text always maps to the same folder, so processes share it and a
    second call costs nothing; nothing is held in memory between calls.
    """
    text = ET.tostring(tree.getroot())
    digest = hashlib.sha256(text + name.encode() + str(Path(source).resolve()).encode()).hexdigest()[:16]
    dest = Path(tempfile.gettempdir()) / "sidbench-aircraft" / f"{name}-{digest}"
    if not (dest / "aircraft" / name / f"{name}.xml").is_file():
        write_root(dest, name, tree, source)
    return dest
