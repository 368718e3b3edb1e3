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

Only what is unambiguous is paired: a record with more files than its components (a
browser's second download ``..._STA000 (1).AT2`` beside ``..._STA000.AT2``), an ``.AT2``
entry that is not a regular file (a FIFO, a dangling or looping link) is named in a
one-line SceneError (or left out with a warning under ``ground.missing: skip``), and the
``.AT2`` files not named as PEER names a component are left out with a warning naming them.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass
from pathlib import Path

from rocksweep.errors import RecordError, SceneError
from rocksweep.outputs import input_problem, shown
from rocksweep.physics.path import check_pair
from rocksweep.physics.records import read_record
from rocksweep.physics.suite import RecordWarning

_RSN = re.compile(r"^(RSN\d+)_", re.IGNORECASE)
_VERTICAL = re.compile(r"(?:[-_]?(?:UP|DWN)|[-_]V)$", re.IGNORECASE)
#: a browser's second download of a file: ``name (1).AT2``, ``name(2).AT2``
_DUPLICATE = re.compile(r"\s*\(\d+\)$")


@dataclass(frozen=True)
class Components:
    """One record's files: its RSN label, H1, H2 (None: missing), the vertical (None:
    none in the folder) and ``extra``: the files beyond two horizontals and one vertical
    (a browser's second download, ``..._STA000 (1).AT2``), which make the pairing
    ambiguous."""

    rsn: str
    h1: Path | None
    h2: Path | None
    up: Path | None
    extra: tuple[Path, ...] = ()

    def missing(self, vertical: bool) -> list[str]:
        """The components this record lacks (``vertical``: the folder's records have one)."""
        out = [n for n, p in (("H1", self.h1), ("H2", self.h2)) if p is None]
        return out + (["UP"] if vertical and self.up is None else [])

    def files(self) -> list[Path]:
        return [p for p in (self.h1, self.h2, self.up, *self.extra) if p is not None]

    def ambiguity(self) -> str | None:
        """Why this record's files cannot be paired (None: they can): more than two
        horizontal or more than one vertical files, named, a browser's duplicate said."""
        if not self.extra:
            return None
        names = ", ".join(p.name for p in sorted(self.files(), key=lambda p: p.name))
        dup = [p.name for p in self.files() if _DUPLICATE.search(p.stem)]
        why = (f"; {', '.join(dup)} looks like a second download of the same file"
               if dup else "")
        return (f"{self.rsn} has more than two horizontal or one vertical files ({names}): "
                f"which are H1, H2 and UP is ambiguous{why}")


def is_vertical(path: Path) -> bool:
    """Whether a PEER file name is a vertical component's (``...-UP.AT2``, ``...DWN``)."""
    return bool(_VERTICAL.search(path.stem))


def peer_components(files: list[Path]) -> tuple[list[Components], list[Path]]:
    """The records of a folder's ``.AT2`` files, grouped by their ``RSN<n>`` prefix (in
    RSN order), and the files that are not named as PEER names them. Of a group's
    horizontals H1 sorts first and H2 second, its vertical is the one vertical file; the
    files beyond those are the record's ``extra`` (``Components.ambiguity``: a record so
    named is never paired)."""
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
        out.append(Components(rsn, hor[0] if hor else None, hor[1] if len(hor) > 1 else None,
                              vert[0] if vert else None, tuple(hor[2:] + vert[1:])))
    return out, odd


def folder_files(folder: Path, skip: bool) -> list[Path]:
    """The ``.AT2`` entries of a folder that are regular files (links followed). An entry
    that is not (a FIFO, a device, a dangling or looping link, a directory) is named in a
    one-line SceneError, or left out with a RecordWarning (``skip``): never dropped
    without a word."""
    key = "ground.records"
    try:
        entries = sorted(folder.iterdir(), key=lambda p: p.name)
    except OSError as err:
        raise SceneError(f"{key}: {shown(folder)}: cannot list the folder "
                         f"({err.strerror or type(err).__name__})") from None
    out = []
    for p in entries:
        if p.suffix.lower() != ".at2":
            continue
        problem = input_problem(p)
        if problem is None:
            out.append(p)
            continue
        what = f"{shown(folder)}: {p.name}: {problem}"
        if not skip:
            raise SceneError(f"{key}: {what}; remove it from the folder (or ground.missing: "
                             "skip)")
        warnings.warn(RecordWarning(f"{key}: {what}: left out"), stacklevel=3)
    return out


def peer_suite(folder: Path, skip: bool) -> tuple:
    """The records of a folder of PEER downloads (``peer_components``): (H1s, H2s, verticals
    (empty: none in the folder), names (H1's file names), files read). A record without
    one of its components, or with more files than its components (ambiguous), or an
    entry that is not a regular file (``folder_files``) is a one-line SceneError naming
    the files, or left out with a RecordWarning (``skip``); the ``.AT2`` files not named
    as PEER names a component are left out with a RecordWarning naming them."""
    key = "ground.records"
    comps, odd = peer_components(folder_files(folder, skip))
    if not comps:
        raise SceneError(f"{key}: {shown(folder)}: no PEER record files in the folder "
                         "(RSN<n>_<EVENT>_<STATION><COMPONENT>.AT2)")
    if odd:
        shown_odd = ", ".join(p.name for p in odd[:5]) + (
            f" and {len(odd) - 5} more" if len(odd) > 5 else "")
        warnings.warn(RecordWarning(
            f"{key}: {shown(folder)}: {len(odd)} .AT2 file{'s' if len(odd) > 1 else ''} not "
            f"named RSN<n>_<EVENT>_<STATION><COMPONENT>.AT2 left out: {shown_odd}"),
            stacklevel=2)
    with_up = any(c.up is not None for c in comps)
    kept = []
    for c in comps:
        why = c.ambiguity()
        miss = c.missing(with_up)
        if why is None and not miss:
            kept.append(c)
            continue
        if why is None:
            found = ", ".join(p.name for p in c.files())
            why = f"{c.rsn} has no {' and no '.join(miss)} file (found {found})"
            need = "H1, H2 and UP" if with_up else "H1 and H2"
            how = f"every record needs {need}"
        else:
            how = "remove the extra files"
        if not skip:
            raise SceneError(f"{key}: {shown(folder)}: {why}; {how} (or ground.missing: "
                             "skip)")
        warnings.warn(RecordWarning(f"{key}: {why}: skipped"), stacklevel=2)
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
