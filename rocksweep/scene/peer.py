"""A folder of PEER NGA-West2 downloads as a suite of multi-component records: the files
paired by their names (no file is read here).

``peer_suite`` reads a folder's records so paired (a one-line SceneError for a record
without one of its components, or a warning where ``ground.missing: skip``).

PEER names each component of a record ``RSN<n>_<EVENT>_<STATION><COMPONENT>.AT2``: the
horizontals end in their azimuth or direction (``RSN1158_KOCAELI_DZC180.AT2``,
``..._DZC270.AT2``; ``RSN9_BORREGO_B-ELC000.AT2``, ``...-ELC090.AT2``), the vertical in
``UP`` or ``DWN`` (``RSN1158_KOCAELI_DZC-UP.AT2``; ``-V``/``V`` in a few older files). The
files of one record share the ``RSN<n>`` prefix. Of its two horizontals H1 is the one whose
file name sorts first (000 before 090, 180 before 270), H2 the other.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from rocksweep.errors import SceneError
from rocksweep.outputs import shown

_RSN = re.compile(r"^(RSN\d+)_", re.IGNORECASE)
_VERTICAL = re.compile(r"(?:[-_]?(?:UP|DWN)|[-_]V)$", re.IGNORECASE)


@dataclass(frozen=True)
class Components:
    """One record's files: its RSN label, H1, H2 (None: missing) and the vertical (None:
    none in the folder)."""

    rsn: str
    h1: Path | None
    h2: Path | None
    up: Path | None

    def missing(self, vertical: bool) -> list[str]:
        """The components this record lacks (``vertical``: the folder's records have one)."""
        out = [n for n, p in (("H1", self.h1), ("H2", self.h2)) if p is None]
        return out + (["UP"] if vertical and self.up is None else [])


def is_vertical(path: Path) -> bool:
    """Whether a PEER file name is a vertical component's (``...-UP.AT2``, ``...DWN``)."""
    return bool(_VERTICAL.search(path.stem))


def peer_components(files: list[Path]) -> tuple[list[Components], list[Path]]:
    """The records of a folder's ``.AT2`` files, grouped by their ``RSN<n>`` prefix (in
    RSN order), and the files that are not named as PEER names them. A group of more than
    two horizontals or verticals keeps its first two / first one by name; the rest are
    returned as unpaired."""
    groups: dict[str, list[Path]] = {}
    odd: list[Path] = []
    for f in sorted(files, key=lambda p: p.name):
        m = _RSN.match(f.name)
        if m is None:
            odd.append(f)
            continue
        groups.setdefault(m.group(1).upper(), []).append(f)
    out = []
    for rsn in sorted(groups, key=lambda k: int(k[3:])):
        fs = groups[rsn]
        vert = [f for f in fs if is_vertical(f)]
        hor = [f for f in fs if not is_vertical(f)]
        odd += hor[2:] + vert[1:]
        out.append(Components(rsn, hor[0] if hor else None, hor[1] if len(hor) > 1 else None,
                              vert[0] if vert else None))
    return out, odd


def peer_suite(folder: Path, skip: bool) -> tuple:
    """The records of a folder of PEER downloads (``peer_components``): (H1s, H2s, verticals
    (empty: none in the folder), names (H1's file names), files read). A record without
    one of its components is a one-line SceneError, or left out with a RecordWarning
    (``skip``)."""
    import warnings

    from rocksweep.errors import RecordError
    from rocksweep.physics.path import check_pair
    from rocksweep.physics.records import read_record
    from rocksweep.physics.suite import RecordWarning

    key = "ground.records"
    files = [p for p in folder.iterdir() if p.suffix.lower() == ".at2" and p.is_file()]
    comps, _ = peer_components(files)
    if not comps:
        raise SceneError(f"{key}: {shown(folder)}: no PEER record files in the folder "
                         "(RSN<n>_<EVENT>_<STATION><COMPONENT>.AT2)")
    with_up = any(c.up is not None for c in comps)
    kept = []
    for c in comps:
        miss = c.missing(with_up)
        if not miss:
            kept.append(c)
            continue
        found = ", ".join(p.name for p in (c.h1, c.h2, c.up) if p is not None)
        what = f"{c.rsn} has no {' and no '.join(miss)} file (found {found})"
        need = "H1, H2 and UP" if with_up else "H1 and H2"
        if not skip:
            raise SceneError(f"{key}: {shown(folder)}: {what}; every record needs {need} "
                             "(or ground.missing: skip)")
        warnings.warn(RecordWarning(f"{key}: {what}: skipped"), stacklevel=2)
    if not kept:
        raise SceneError(f"{key}: {shown(folder)}: no record has all its components")
    h1s, h2s, ups = [], [], []
    for c in kept:
        try:
            one = [read_record(p) for p in (c.h1, c.h2, *([c.up] if with_up else []))]
        except RecordError as err:
            raise SceneError(f"{key}: {err}") from None
        # H2 must share H1's DT; the vertical is resampled onto H1's samples where it
        # acts, as one record's ground.vertical is (``records.vertical_samples``)
        why = check_pair(one[0], one[1])
        if why is not None:
            raise SceneError(f"{key}: {c.rsn}: H2 {one[1].name}: {why}")
        h1s.append(one[0])
        h2s.append(one[1])
        ups.append(one[2] if with_up else None)
    read = tuple(str(p) for c in kept for p in (c.h1, c.h2, c.up) if p is not None)
    return (h1s, tuple(h2s), tuple(ups) if with_up else (), [c.h1.name for c in kept],
            read)
