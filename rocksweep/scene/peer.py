"""A folder of PEER NGA-West2 downloads as a suite of multi-component records: the files
paired by their names (no file is read here).

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
