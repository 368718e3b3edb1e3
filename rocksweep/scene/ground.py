"""The ``ground:`` section: one record (``ground.record``, ``h2``, ``vertical``) or a suite
(``ground.records``: paths, globs, listings or a PEER folder; its scaling ``ground.scale``).

Paths are relative to the scene file's folder; every input is read through
``rocksweep.inputs`` (regular files, bounded sizes). Called by ``scene.parse``.
"""

from __future__ import annotations

import math
import os
from glob import glob, has_magic
from pathlib import Path
from typing import Any

import numpy as np

from rocksweep.errors import RecordError, SceneError, SuiteError
from rocksweep.inputs import decode_text, read_input
from rocksweep.outputs import input_problem, is_input, shown
from rocksweep.physics.records import GroundRecord, read_record
from rocksweep.physics.suite import AVGSA_RANGE, Suite, make_suite
from rocksweep.scene.peer import peer_suite
from rocksweep.scene.sections import axis_spec, axis_values, choice
from rocksweep.schema import (
    KEYS,
    as_float,
    check_values,
    fmt,
    is_number,
)
from rocksweep.vocab.ground import (
    DEFAULT_PERIODS,
    H1,
    MISSING_ERROR,
    MISSING_SKIP,
    RECORD_IMS,
    ROTD50,
    ROTD50_IMS,
    SCALE_IMS,
)


def ground_record(ground: dict, base: Path | None, key: str = "record") -> GroundRecord:
    """The record of a ``ground`` section (``ground.record``; key ``h2``: the second
    horizontal, ``vertical``: the vertical component), read (and hashed) now."""
    spec = KEYS[f"ground.{key}"]
    v = ground[key]
    if not (isinstance(v, str) and v.strip()):
        raise SceneError(f"ground.{key} = {fmt(v)}: {spec.allowed}")
    path = _where(v, base)
    try:
        return read_record(path)
    except RecordError as err:
        raise SceneError(f"ground.{key}: {err}") from None


def _where(v: str, base: Path | None) -> Path:
    """A path of the scene, relative to ``base`` (the scene file's directory), absolute:
    the file records where it read a record (spectra re-read it)."""
    path = Path(v).expanduser()
    if not path.is_absolute() and base is not None:
        path = base / path
    return path.absolute()


# Most records a suite may hold (a scene's axis holds at most MAX_AXIS_VALUES values;
# FEMA P695's sets are 44 and 28 records).
MAX_RECORDS = 10_000
MAX_LISTING_BYTES = 16 << 20  # [bytes] a listing of MAX_RECORDS paths is far less
_LIST_SUFFIXES = (".txt", ".list", ".lst")


def _is_listing(path: Path) -> bool:
    """A text file listing record paths (suffix .txt, .list or .lst, and its first line
    that is not blank or a # comment is not two numbers: a two-column record's is).
    A file of that suffix that is not text (UTF-16, random bytes) counts as a listing:
    ``_listing`` says why it cannot be read."""
    if path.suffix.lower() not in _LIST_SUFFIXES or input_problem(path) is not None:
        return False
    try:
        with path.open("rb") as fh:
            head = fh.read(1 << 16)
    except OSError:
        return False
    try:
        text = head.decode("utf-8-sig")
    except UnicodeDecodeError:
        return True
    if "\0" in text:
        return True
    for line in text.splitlines():
        t = line.strip()
        if not t or t.startswith("#"):
            continue
        fields = t.replace(",", " ").split()
        try:
            [float(x) for x in fields]
        except ValueError:
            return True
        return len(fields) != 2  # a record's row is two numbers; '123' names a file
    return True


def _listing(path: Path, shown_as: str) -> list[tuple[int, str]]:
    """(line number, entry) of a listing: UTF-8 text (a byte-order mark, as Notepad
    saves it, is skipped), one path a line, blank lines and # comments skipped."""
    key = "ground.records"
    try:  # the one guard of input files: regular, bounded, UTF-8 text
        text = decode_text(read_input(path, "listing", SceneError,
                                      max_bytes=MAX_LISTING_BYTES),
                           shown_as, SceneError, "listing of record paths (one a line)")
    except SceneError as err:
        raise SceneError(f"{key}: {err}") from None
    return [(i + 1, ln.strip()) for i, ln in enumerate(text.splitlines())
            if ln.strip() and not ln.strip().startswith("#")]


def _record_paths(spec: Any, base: Path | None) -> tuple[list[Path], list[Path],
                                                          dict[Path, str]]:
    """The files of ``ground.records`` in order: each entry a path (a file that exists is
    that file, even if its name holds glob characters such as ``r[1].AT2``), else a glob
    (sorted), or a listing (one path a line, relative to the listing's directory; #
    comments; a listed path is a path, never a glob). Returns (records, listings read,
    where each listed record was named: 'suite.txt, line 3')."""
    key = "ground.records"
    entries = spec if isinstance(spec, list) else [spec]
    if isinstance(spec, list) and not spec:
        raise SceneError(f"{key} = []: an empty list; {KEYS[key].allowed}")
    out: list[Path] = []
    listings: list[Path] = []
    named: dict[Path, str] = {}
    for e in entries:
        if not (isinstance(e, str) and e.strip()):
            raise SceneError(f"{key} = {fmt(e)}: {KEYS[key].allowed}")
        if "\0" in e:
            raise SceneError(f"{key} = {fmt(e)}: a NUL byte in a file name; no file can "
                             "have it")
        path = _where(e, base)
        if has_magic(e) and not os.path.lexists(path):
            pattern = str(path)
            # a folder it matches is no record; a FIFO or a dangling link is named below
            found = sorted(Path(p) for p in glob(pattern) if not Path(p).is_dir())
            if not found:
                raise SceneError(f"{key}: {e!r} matches no file (looked for {pattern})")
            out.extend(found)
            continue
        problem = input_problem(path)
        if problem is not None and problem != "no such file":
            raise SceneError(f"{key}: {shown(path)}: {problem}")
        if _is_listing(path):
            listings.append(path)
            listed = _listing(path, shown(e))
            if not listed:
                raise SceneError(f"{key}: {e} lists no record file")
            for line, entry in listed:
                where = f"{shown(e)}, line {line}"
                if "\0" in entry:
                    raise SceneError(f"{key}: {where}: a NUL byte in a file name")
                p = _where(entry, path.parent)
                if is_input(p, [path]) or (input_problem(p) is None and _is_listing(p)):
                    what = "the listing itself" if is_input(p, [path]) else "a listing"
                    raise SceneError(f"{key}: {where}: {shown(entry)} is {what}; a listing "
                                     "names record files (.AT2 or two-column), one a line")
                named[p] = where
                out.append(p)
                if len(out) > MAX_RECORDS:
                    break
        else:
            out.append(path)
        if len(out) > MAX_RECORDS:
            break
    if len(out) > MAX_RECORDS:
        raise SceneError(f"{key}: more than {MAX_RECORDS:,} records; split the suite")
    seen: dict[str, Path] = {}
    for path in out:
        problem = input_problem(path)
        if problem is not None:
            where = f"{named[path]}: " if path in named else ""
            raise SceneError(f"{key}: {where}{shown(path)}: {problem}")
        real = os.path.realpath(path)
        if real in seen:
            raise SceneError(f"{key}: {shown(path)} is listed twice (each record once: the "
                             "file names label the record dimension)")
        seen[real] = path
    names: dict[str, Path] = {}
    for path in out:
        if path.name in names:
            raise SceneError(f"{key}: two records named {path.name} ({names[path.name]} and "
                             f"{path}): the file names label the record dimension, rename "
                             "one")
        names[path.name] = path
    return out, listings, named


def _periods(ground: dict) -> list[float]:
    key = "ground.periods"
    spec = ground.get("periods", list(DEFAULT_PERIODS))
    values = spec if isinstance(spec, list) else [spec]
    if not values or not all(is_number(v) for v in values):
        raise SceneError(f"{key} = {fmt(spec)}: {KEYS[key].allowed}")
    out = [as_float(v) for v in values]
    for v in out:
        if not (0.0 <= v <= 100.0):
            raise SceneError(f"{key} = {fmt(v)}: {KEYS[key].allowed}")
    if len(set(out)) != len(out):
        raise SceneError(f"{key} = {fmt(spec)}: a period is given twice")
    return out


def _scale(ground: dict) -> tuple[str | None, str, Any, float, float]:
    """(im or None, form, values spec, period [s] or NaN, cloud factor or NaN) of
    ``ground.scale``."""
    key = "ground.scale"
    v = ground.get("scale", "none")
    if v is None or v == "none":
        return None, "", None, math.nan, 1.0
    if not isinstance(v, dict):
        raise SceneError(f"{key} = {fmt(v)}: {KEYS[key].allowed}")
    if "factor" in v:
        extra = sorted(set(v) - {"factor"})
        if extra:
            raise SceneError(f"{key}.{extra[0]}: not with factor ({KEYS[key].allowed})")
        f = v["factor"]
        if not is_number(f) or check_values(f"{key}.factor", np.array([as_float(f)])):
            raise SceneError(f"{key}.factor = {fmt(f)}: {KEYS[key + '.factor'].allowed}")
        return None, "", None, math.nan, as_float(f)
    for k in v:
        if k not in ("im", "values", "period", "component"):
            raise SceneError(f"{key}.{k}: unknown key (allowed: im, values, period, "
                             "component; or factor alone)")
    im = v.get("im")
    if isinstance(im, str) and RECORD_IMS.get(im, ("", "", 1))[2] == 0:
        raise SceneError(f"{key}.im = {im}: does not change when a record is scaled, so no "
                         f"factor can reach a stripe of it; {KEYS[key + '.im'].allowed}")
    if not isinstance(im, str) or im not in SCALE_IMS:
        raise SceneError(f"{key}.im = {fmt(im)}: {KEYS[key + '.im'].allowed}")
    if v.get("values") is None:
        raise SceneError(f"{key}.values: missing required key (the stripes' {im} values: "
                         "a number, a list of numbers or a range {start, stop, num})")
    form, spec, _ = axis_spec(f"{key}.values", v["values"])
    period = math.nan
    if im == "Sa":
        T = v.get("period")
        if T is None:
            raise SceneError(f"{key}.period: missing required key (Sa's period [s])")
        if not is_number(T) or check_values(f"{key}.period", np.array([as_float(T)])):
            raise SceneError(f"{key}.period = {fmt(T)}: {KEYS[key + '.period'].allowed}")
        period = as_float(T)
    elif v.get("period") is not None:
        raise SceneError(f"{key}.period = {fmt(v['period'])}: only with im: Sa")
    return im, form, spec, period, math.nan


def _avgsa(ground: dict, period: float) -> tuple[tuple[float, float], str]:
    """AvgSa's period range [s] and how it was chosen (``rocksweep.physics.suite``):
    ``ground.avgsa``, else AVGSA_RANGE x T_ref, T_ref the Sa stripes' period or 2 pi / p."""
    key = "ground.avgsa"
    spec = ground.get("avgsa")
    if spec is not None:
        ok = (isinstance(spec, list) and len(spec) == 2 and all(is_number(v) for v in spec))
        lo, hi = (as_float(spec[0]), as_float(spec[1])) if ok else (math.nan, math.nan)
        if not (ok and 0.0 < lo <= hi <= 100.0):
            raise SceneError(f"{key} = {fmt(spec)}: {KEYS[key].allowed}")
        return (lo, hi), f"ground.avgsa = [{lo:g}, {hi:g}] s"
    if math.isfinite(period):
        t_ref, why = period, "scale.period"
    else:
        form, pspec, _ = axis_spec("ground.p", ground["p"])
        p = axis_values("ground.p", form, pspec)
        t_ref = 2.0 * math.pi / float(np.exp(np.mean(np.log(p))))
        why = "2 pi / p" if p.size == 1 else "2 pi / p (geometric mean of the swept p)"
    a, b = AVGSA_RANGE
    return (a * t_ref, b * t_ref), f"{a:g}-{b:g} x T_ref, T_ref = {why} = {t_ref:.4g} s"


def ground_suite(ground: dict, base: Path | None, given: tuple[GroundRecord, ...] | None = None
           ) -> tuple[Suite, tuple[str, str, Any] | None, tuple[str, ...]]:
    """The suite of a ``ground.records`` section (records read and hashed, IMs computed
    now), the stripe axis's (name, form, spec), None for a cloud, and the files read
    (records and listings). given: the records already read (a result file's stored
    copies): ``ground.records`` is then not read."""
    for k in ("record", "A_ratio"):
        if ground.get(k) is not None:
            other = ("ground.scale: {im: PGA_ratio, values: ...}" if k == "A_ratio"
                     else "a list in ground.records")
            raise SceneError(f"ground.{k}: not with ground.records (use {other})")
    im, form, spec, period, factor = _scale(ground)
    scale = ground.get("scale")
    component = choice("ground.scale.component",
                       scale.get("component") if isinstance(scale, dict) else None)
    missing = choice("ground.missing", ground.get("missing"))
    folder = _peer_folder(ground["records"], base)
    if folder is None and missing != MISSING_ERROR:
        raise SceneError("ground.missing: applies to a folder of PEER downloads "
                         "(ground.records: FOLDER)")
    acts = ground.get("vertical")
    if acts is not None and (folder is None or not isinstance(acts, bool)):
        raise SceneError(f"ground.vertical = {fmt(acts)}: with ground.records, true or false "
                         "for a folder of PEER downloads (whether each record's UP file acts "
                         "on the body); a path works with one ground.record")
    h2: tuple = ()
    vertical: tuple = ()
    read: tuple[str, ...] = ()
    if folder is not None:  # read again on a rebuild: the pairs are the folder's
        records, h2, vertical, names, read = peer_suite(folder, missing == MISSING_SKIP)
        if acts and not vertical:
            raise SceneError(f"ground.vertical = true: {shown(folder)} has no vertical (UP) "
                             "files; give them, or leave ground.vertical out")
    elif given is not None:
        records = list(given)
        names = [Path(r.source).name for r in records]
    else:
        paths, listings, named = _record_paths(ground["records"], base)
        records = []
        for path in paths:
            try:
                records.append(read_record(path))
            except RecordError as err:
                where = f"{named[path]}: " if path in named else ""
                raise SceneError(f"ground.records: {where}{err}") from None
        names = [p.name for p in paths]
        read = tuple(str(p) for p in (*paths, *listings))
    if component == ROTD50 and not h2:
        raise SceneError(f"ground.scale.component = {fmt(ROTD50)}: needs both horizontals of "
                         "every record (ground.records: a folder of PEER downloads)")
    if component == ROTD50 and im is None:
        raise SceneError(f"ground.scale.component = {fmt(ROTD50)}: scales stripes "
                         "(ground.scale: {im: ..., values: ...})")
    if component == ROTD50 and im not in ROTD50_IMS:
        raise SceneError(f"ground.scale.component = {fmt(ROTD50)}: with ground.scale.im = "
                         f"{im}; RotD50 (the median over orientations of a peak, Boore 2010) "
                         f"is taken of {', '.join(ROTD50_IMS)} stripes; use component "
                         f"{fmt(H1)} for {im}")
    values = axis_values("ground.scale.values", form, spec).tolist() if im else []
    try:
        suite = make_suite(records, names, im, values, period, factor,
                           _periods(ground), *_avgsa(ground, period), h2=h2,
                           vertical=vertical, component=component,
                           vertical_acts=acts is not False)
    except SuiteError as err:
        raise SceneError(f"ground.records: {err}") from None
    return suite, ((im, form, spec) if im else None), read


def _peer_folder(spec: Any, base: Path | None) -> Path | None:
    """The folder of ``ground.records: FOLDER`` (one entry that is a directory), else
    None."""
    entry = spec[0] if isinstance(spec, list) and len(spec) == 1 else spec
    if not (isinstance(entry, str) and entry.strip()) or "\0" in entry:
        return None
    path = _where(entry, base)
    return path if path.is_dir() else None


