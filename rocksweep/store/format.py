"""The sweep result format (HDF5 through h5py): its constants and metadata, and the
making of a new file's contents: ``metadata``, built once, written by ``initialise``.

Layout (netCDF-4 / CF-1.10, so ``xarray.open_dataset(path, engine="h5netcdf")`` and
netCDF-4 readers open it):

- one dataset per swept axis, named after it (``shape``, a body key, ``lam``, ``A_ratio``,
  ``w_over_p``), holding its values and made an HDF5 dimension scale;
- one 0-d dataset per unswept axis (a scalar coordinate, listed in each variable's
  ``coordinates`` attribute);
- one dataset per stored variable (``rocksweep.compute.sweep.VARIABLES``) with the grid's
  dimensions attached; ``outcome`` is -1 where a point is not computed yet;
- every variable and coordinate has ``long_name`` and (but the pulse shape and the flag
  variables ``outcome``, ``status``) CF ``units``: ``"rad"`` for angles, ``"1"`` for
  everything else, which is a pure number: Pi groups, counts, theta/alpha_ref, energies
  / E_ref, and times p*t (``t_overturn``: its ``long_name`` says p*t, its
  ``rocksweep_units`` the scale, here ``"1/p"``);
- adaptive sweeps (``rocksweep sweep --adaptive``, ``rocksweep.compute.adaptive``) add an int8
  variable ``computed`` (0 filled: the point was not computed, its ``outcome`` is the class
  of the uniform cell around it and every other variable keeps its "not computed" fill
  value; 1 computed; 2 an audit point that agreed with its fill; 3 one that disagreed; CF
  ``flag_values``/``flag_meanings``), the settings as attributes ``adaptive`` (int8 1),
  ``adaptive_axes``, ``adaptive_coarse``, ``adaptive_margin``, ``adaptive_final_margin``,
  ``adaptive_audit``, ``adaptive_seed``, ``adaptive_threshold`` (also in the resolved
  scene, so a resume with other settings is refused), and the counts ``points_computed``,
  ``points_filled``, ``points_audited``, ``audit_misses`` (fixed size, updated in place).
  While an adaptive sweep runs, ``outcome`` is -1 at the points not decided yet; its
  last session writes the filled classes;
- global attributes: ``Conventions`` (``CF-1.10``), ``title``, ``source``, ``history``
  (one line per session: time, host, backend, rocksweep version, points done), the scene
  YAML verbatim and its resolved form (``rocksweep.store.identity``), the resolved
  numerics, versions, times, totals, ``host`` and ``backend`` of the latest session and
  the format version. ``complete`` and ``energy`` are int8 0/1 (netCDF has no boolean
  attribute; HDF5 enums are lost);
- a record sweep keeps its record (group ``record``: the file's bytes and the samples).

The attributes a session changes (``SESSION_ATTRS``) have fixed-size types (numbers,
fixed-length strings) and are overwritten in place (``rocksweep.store.writer``).
"""

from __future__ import annotations

import json
import math
import platform
from dataclasses import dataclass
from typing import Any

import h5py
import numpy as np

from rocksweep import fields
from rocksweep._version import __version__
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics import floor
from rocksweep.scene.model import Scene
from rocksweep.store._common import fixed_ascii, utc_now
from rocksweep.store.identity import files_resolved, resolved_scene
from rocksweep.vocab.axes import alpha_symbol
from rocksweep.vocab.outcomes import COMPUTED_FLAGS, COMPUTED_MEANING, OUTCOME_WORDS, STATUS_WORDS
from rocksweep.vocab.phases import PHASE_CODE

FORMAT = "rocksweep-sweep"
# 1: first release; 2: CF attributes (units, Conventions, int8 flags), fixed-size session
# attributes, history/host/backend. This version reads both and resumes both.
FORMAT_VERSION = 2
CONVENTIONS = "CF-1.10"

# Size of the ``history`` attribute [bytes]: fixed, so a session rewrites it in place;
# about 30 sessions of one line each (the oldest are dropped beyond that).
HISTORY_BYTES = 4096

# The attributes a session changes -> fixed-size dtype (written in place, never resized).
SESSION_ATTRS: dict[str, str] = {
    "sessions": "int64",
    "last_started": "S32",
    "last_finished": "S32",
    "finished": "S32",
    "wall_time": "float64",
    "cpu_time": "float64",
    "points_done": "int64",
    "complete": "int8",
    "steps_total": "int64",
    "event_steps_total": "int64",
    # RK4 evaluations of the certification's runs (part of the steps above; -1: not
    # recorded, a file of a rocksweep before the count resumed)
    "refine_evaluations": "int64",
    "host": "S256",
    "backend": "S256",
    "history": f"S{HISTORY_BYTES}",
}

# Counts an adaptive sweep updates at the end of every session (in place, like
# SESSION_ATTRS): from ``rocksweep.compute.adaptive.stats_of`` of the ``computed`` flags.
ADAPTIVE_COUNT_ATTRS: dict[str, str] = {
    "points_computed": "int64",
    "points_filled": "int64",
    "points_audited": "int64",
    "audit_misses": "int64",
}
# The ``computed`` variable of adaptive sweeps: (dtype, fill, description), flag meanings.
COMPUTED_VARIABLE = ("int8", 0, "adaptive sweep: " + ", ".join(
    f"{c} {m}" for c, m in COMPUTED_MEANING.items()) + "; other variables of a filled "
    "point at their fill values")

# Variables whose values are codes (CF flag_values / flag_masks): no units.
FLAG_VARIABLES = ("outcome", "status", "computed", "regime")


def versions() -> dict[str, str]:
    """Versions of rocksweep and the libraries that shape its results."""
    import numba  # lazy: numba, scipy (+0.2 s)

    return {"rocksweep": __version__, "numba": numba.__version__, "numpy": np.__version__,
            "h5py": h5py.__version__, "hdf5": h5py.version.hdf5_version,
            "python": platform.python_version()}


def variables_for(stored: dict) -> dict:
    """The per-point variables of a file from its resolved scene (``computed`` in the
    files of adaptive sweeps)."""

    return {**fields.variables(bool(stored.get("energy")), bool(stored.get("contact")),
                               bool(stored.get("check")),
                               bool((stored.get("path") or {}).get("floor")),
                               "body.mu" in (stored.get("axes") or {})),
            **({"computed": COMPUTED_VARIABLE} if stored.get("adaptive") else {})}


def flat_slabs(shape: tuple[int, ...], start: int, stop: int) -> list[tuple[tuple, int, int]]:
    """Split the flat (C-order) range [start, stop) of an array of ``shape`` into boxes.

    Returns ``(index, a, b)``: ``array[index]`` holds the flat elements a..b-1 (in order).
    At most 2 * len(shape) - 1 boxes.
    """
    if start >= stop:
        return []
    if len(shape) == 0:
        return [((), 0, 1)]
    if len(shape) == 1:
        return [((slice(start, stop),), start, stop)]
    inner = math.prod(shape[1:])
    i0, r0 = divmod(start, inner)
    if i0 == (stop - 1) // inner:  # within one sub-array
        return [((slice(i0, i0 + 1), *idx), i0 * inner + a, i0 * inner + b)
                for idx, a, b in flat_slabs(shape[1:], r0, stop - i0 * inner)]
    out = []
    if r0:
        out += flat_slabs(shape, start, (i0 + 1) * inner)
        i0 += 1
    i1, r1 = divmod(stop, inner)
    if i1 > i0:
        out.append(((slice(i0, i1), *(slice(None),) * (len(shape) - 1)),
                    i0 * inner, i1 * inner))
    if r1:
        out += flat_slabs(shape, i1 * inner, stop)
    return out


def file_bytes(scene: Scene, adaptive: bool = False) -> int:
    """Bytes the datasets of a result file of ``scene`` take (all allocated when the
    file is made): every variable's dtype size x grid points, plus the coordinates;
    adaptive: with the ``computed`` flags."""
    per_point = sum(np.dtype(dt).itemsize for dt, _, _ in scene.variables().values())
    per_point += adaptive
    coords = sum(16 * len(a.values) for a in scene.axes)
    su = scene.suite
    if su is not None:  # the per-record variables (sha256: 64 characters) and factors
        R = len(su.records)
        coords += R * (8 * (5 + len(su.periods)) + 96) + 8 * R * max(1, len(su.levels))
    return per_point * scene.size + coords


@dataclass(frozen=True)
class Metadata:
    """A new result file's contents but its points, built once (``metadata``) and written
    by ``initialise``, which computes nothing: attrs, the global attributes in order;
    coords, the swept axes (dimension scales, in the grid's order) and scalars, the
    unswept ones (0-d coordinates): name -> (values, attributes); variables: name ->
    (dtype, fill value, attributes), every per-point variable; nbytes: what its datasets
    take (``file_bytes``); scene: whose record or suite's files the file keeps."""

    scene: Scene
    attrs: dict[str, Any]
    coords: dict[str, tuple[Any, dict[str, Any]]]
    scalars: dict[str, tuple[Any, dict[str, Any]]]
    variables: dict[str, tuple[str, Any, dict[str, Any]]]
    nbytes: int


def metadata(scene: Scene, overrides: tuple[str, ...] = (),
             adaptive: dict | None = None) -> Metadata:
    """The ``Metadata`` of a new result file of ``scene`` (made with ``overrides``; adaptive:
    the resolved settings of an adaptive sweep, ``adaptive.Options.resolved``)."""
    vers = versions()
    a: dict[str, Any] = {}
    a["Conventions"] = CONVENTIONS
    a["title"] = scene.name
    a["source"] = f"rocksweep {vers['rocksweep']} (rocksweep sweep)"
    a["comment"] = ("Stability diagram of a flexible rocking oscillator (Zhu, Chatzis & "
                    "Acikgoz). outcome -1 marks points not computed. complete and energy "
                    "are flags: int8 1 true, 0 false. Times are p*t and all variables "
                    "are dimensionless (units 1; rocksweep_units names the scale).")
    a["rocksweep_format"] = FORMAT
    a["format_version"] = FORMAT_VERSION
    a["scene"] = scene.text
    a["scene_kind"] = scene.kind
    a["scene_resolved"] = json.dumps(resolved_scene(scene, overrides, adaptive))
    a["overrides"] = json.dumps(list(overrides))
    n = scene.numerics
    a["numerics"] = json.dumps(n.as_dict())
    a["accuracy"] = n.describe()
    a["steps_per_period"] = n.steps_per_period
    a["event_tol"] = n.event_tol
    a["horizon"] = n.horizon
    a["energy"] = np.int8(bool(scene.energy))
    # the record and its components: name, SHA-256, NPTS, DT [s], PGA [g] (and IMs)
    for role, attrs in files_resolved(scene).items():
        for k, v in attrs.items():
            a[f"{role}_{k}"] = v
    if scene.path is not None:  # the orientation's second component and the building
        for k, v in path_attrs(scene).items():
            a[k] = v
    for k, v in scene.physical_summary().items():  # a physical body's p [rad/s]
        a[k] = v
    if scene.suite is not None:  # the stripes' IM ("none": a cloud) and Sa's period [s]
        a["scale_im"] = scene.suite.im or "none"
        a["scale_period"] = float(scene.suite.period)
        a["scale_component"] = scene.suite.component  # H1, or RotD50 of both horizontals
    for k, v in vers.items():
        a[f"{k}_version"] = v
    a["started"] = utc_now()
    a["points_total"] = np.int64(scene.size)
    # fixed-size attributes, updated in place by every session
    zeros = {"S": "", "i": 0, "f": 0.0}
    for name, dtype in SESSION_ATTRS.items():
        kind = np.dtype(dtype).kind
        a[name] = fixed_ascii("", dtype) if kind == "S" else np.array(zeros[kind], dtype)
    if adaptive is not None:
        a["adaptive"] = np.int8(1)
        a["adaptive_axes"] = " ".join(adaptive["axes"])
        for k in ("coarse", "margin", "final_margin", "seed"):
            a[f"adaptive_{k}"] = np.int64(adaptive[k])
        for k in ("audit", "threshold"):
            a[f"adaptive_{k}"] = np.float64(adaptive[k])
        for name, dtype in ADAPTIVE_COUNT_ATTRS.items():
            a[name] = np.array(0, dtype)
        a["comment"] = (a.pop("comment") + " Adaptive sweep: computed flags each point "
                        "(0 filled: outcome from the uniform cell around it, the other "
                        "variables at their fill values; 1 computed; 2/3 audit points that "
                        "agreed/disagreed with their fill).")

    words = h5py.string_dtype()
    coords = {axis.name: (np.array(axis.values, dtype=words) if axis.name in fields.WORD_AXES
                          else np.asarray(axis.values, float),
                          coord_attrs(axis, scene.kind))
              for axis in scene.swept}
    scalars = {axis.name: (np.array(axis.values[0], dtype=words)
                           if axis.name in fields.WORD_AXES else float(axis.values[0]),
                           coord_attrs(axis, scene.kind))
               for axis in scene.axes if not axis.swept}
    specs = dict(scene.variables())
    if adaptive is not None:
        specs["computed"] = COMPUTED_VARIABLE
    variables = {name: (dtype, fill, variable_attrs(name, text, scene.kind, tuple(scalars)))
                 for name, (dtype, fill, text) in specs.items()}
    return Metadata(scene, a, coords, scalars, variables,
                    file_bytes(scene, adaptive is not None))


def variable_attrs(name: str, text: str, kind: str, scalars: tuple[str, ...]
                   ) -> dict[str, Any]:
    """The attributes of the per-point variable ``name`` (text: its description, for one
    that is not a result field) in a file of a ``kind`` body whose unswept axes are
    ``scalars``: CF units and flags, long_name, rocksweep_units, coordinates."""
    out: dict[str, Any] = {}
    f_ = fields.BY_NAME.get(name)
    meta = (fields.field_attrs(f_, kind) if f_ is not None
            else {"long_name": "peak floor acceleration", "description": text,
                  "units": "g"} if name == fields.FLOOR_PFA
            else {"long_name": "computed flag", "description": text})
    if name in FLAG_VARIABLES:
        meta.pop("rocksweep_units", None)
    else:
        out["units"] = "1"
    out.update(meta)
    if name == "outcome":  # CF-style flag attributes, for xarray users
        out["flag_values"] = np.array(list(OUTCOME_WORDS), np.int8)
        out["flag_meanings"] = " ".join(OUTCOME_WORDS.values())
    elif name == "computed":
        out["flag_values"] = np.array(list(COMPUTED_FLAGS), np.int8)
        out["flag_meanings"] = " ".join(COMPUTED_FLAGS.values())
    elif name == "regime":  # the contact phases visited, a bit each (vocab.phases)
        out["flag_masks"] = np.array([1 << c for c in PHASE_CODE.values()], np.int8)
        out["flag_meanings"] = " ".join(PHASE_CODE)
    elif name == "status":
        out["flag_masks"] = np.array(list(STATUS_WORDS), np.int32)
        out["flag_meanings"] = " ".join(STATUS_WORDS.values())
        out["flagged_mask"] = np.int32(L.STATUS_FLAGGED)
    if scalars:
        out["coordinates"] = " ".join(scalars)
    return out


def initialise(f: h5py.File, meta: Metadata) -> None:
    """Write ``meta`` into the new, empty file ``f``: the attributes, the record or suite
    files kept, the coordinates, every variable allocated in full at its fill value (no
    metadata changes later), and a suite's per-record variables."""
    for k, v in meta.attrs.items():
        f.attrs[k] = v
    scene = meta.scene
    for role, rec in scene.ground_files().items():
        _store_record(f, role, rec)
    if scene.suite is not None:
        _store_suite_records(f, scene.suite)
    scales = []
    for name, (data, attrs) in meta.coords.items():
        ds = f.create_dataset(name, data=data)
        ds.make_scale(name)
        ds.attrs.update(attrs)
        scales.append(ds)
    for name, (data, attrs) in meta.scalars.items():
        f.create_dataset(name, data=data).attrs.update(attrs)
    for name, (dtype, fill, attrs) in meta.variables.items():
        dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
        dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)  # no metadata changes later
        ds = f.create_dataset(name, shape=scene.shape, dtype=dtype, fillvalue=fill,
                              dcpl=dcpl, fill_time="alloc")
        ds.attrs.update(attrs)
        for i, sc in enumerate(scales):
            ds.dims[i].attach_scale(sc)
    if scene.suite is not None:
        _write_suite(f, scene, {s.name.lstrip("/"): s for s in scales})


def path_attrs(scene: Scene) -> dict[str, str]:
    """The attributes stating a scene's excitation path: ``floor`` (the building, one
    line, and the stopping rule of its ring-down) and ``ground_h2`` (the second horizontal
    component: name, SHA-256, path read)."""
    out = {}
    if scene.floor:
        out["floor"] = (f"{scene.floor_words()}; cascade (the body does not load the "
                        "building); floor motion a_g + sum Gamma phi q'' exact for the "
                        "piecewise-linear ground at >= "
                        f"{floor.POINTS_PER_PERIOD} samples per period, ring-down until "
                        f"below {floor.RINGDOWN_SHARE:g} of the floor's peak; floor.period "
                        "in s" + ("" if scene.recorded else
                                  f" with the pulse timed by p = {scene.path.p:g} rad/s"))
    h2 = [r for r in scene.path.h2 if r is not None]
    if h2 and scene.suite is None:
        out["ground_h2"] = f"{h2[0].name} sha256 {h2[0].sha256} ({h2[0].source})"
    return out


def suite_variables(scene: Scene) -> dict[str, tuple[tuple[str, ...], np.ndarray]]:
    """The per-record variables of a suite scene's result: name -> (dims, values):
    ``record_pga`` [g], ``record_pgv`` [m/s], ``record_sa`` (record, period) [g],
    ``record_npts``, ``record_dt`` [s], ``record_duration`` [s], ``record_sha256``, and
    ``scale_factor``: (record, stripe) when scaled, with the swept slenderness (PGA_ratio,
    PGV_ratio) and p (PGV_ratio) when the factor depends on them; (record,) for a cloud."""
    su = scene.suite
    R = len(su.records)
    out: dict[str, tuple[tuple[str, ...], np.ndarray]] = {
        "record_pga": (("record",), np.asarray(su.pga, float)),
        "record_pgv": (("record",), np.asarray(su.pgv, float)),
        "record_sa": (("record", "period"), np.asarray(su.sa, float)),
        **{k: (("record",), v) for k, v in su.record_ims().items() if k not in (
            "record_pga", "record_pgv")},  # Arias, CAV, D5-95, PGV/PGA, AvgSa (RECORD_IMS)
        "record_v_end": (("record",), np.asarray(su.v_end, float)),
        "record_npts": (("record",), np.array([r.npts for r in su.records], np.int64)),
        "record_dt": (("record",), np.array([r.dt for r in su.records], float)),
        "record_duration": (("record",), np.array([r.duration for r in su.records], float)),
        "record_sha256": (("record",), np.array([r.sha256 for r in su.records], object)),
        **{k: (("record",), v) for k, v in su.vertical_ims().items()},
        **({"record_rotd50": (("record",), np.asarray(su.rotd50, float))}
           if su.rotd50 is not None else {}),
    }
    r = np.arange(R)
    if su.im is None:
        out["scale_factor"] = (("record",), su.factors(r, None, np.zeros(R), np.ones(R)))
        return out
    dims = ["record", su.im]
    shape = [R, len(su.levels)]
    alpha_key = alpha_symbol(scene.kind)
    alpha = np.asarray(scene.axis(alpha_key).values, float)
    p = np.asarray(scene.axis("p").values, float)
    dep = su.scale_dependence()
    if "alpha_ref" in dep and scene.axis(alpha_key).swept:
        dims.append(alpha_key)
        shape.append(alpha.size)
    else:
        alpha = alpha[:1]
    if "p" in dep and scene.axis("p").swept:
        dims.append("p")
        shape.append(p.size)
    else:
        p = p[:1]
    grids = np.meshgrid(r, np.arange(len(su.levels)), alpha, p, indexing="ij")
    fac = su.factors(grids[0], grids[1], grids[2], grids[3]).reshape(shape)
    out["scale_factor"] = (tuple(dims), fac)
    return out


def _write_suite(f: h5py.File, scene: Scene, scales: dict) -> None:
    """The suite's per-record variables (``suite_variables``) with their dimension scales
    (``period`` made here) and CF attributes (``fields.RECORD_VARIABLES``)."""
    su = scene.suite
    per = f.create_dataset("period", data=np.asarray(su.periods, float))
    per.make_scale("period")
    for k, v in fields.axis_attrs("period").items():
        per.attrs[k] = v
    scales = {**scales, "period": per}
    for name, (dims, values) in suite_variables(scene).items():
        if values.dtype == object:
            ds = f.create_dataset(name, data=values.astype(str).astype(object),
                                  dtype=h5py.string_dtype())
        else:
            ds = f.create_dataset(name, data=values)
        long_name, units, text = fields.RECORD_VARIABLES[name]
        ds.attrs["long_name"] = long_name
        if units is not None:
            ds.attrs["units"] = units
        ds.attrs["description"] = text
        if name == "record_avgsa":  # its period range and how it was chosen
            ds.attrs["avgsa_periods"] = np.asarray(su.avgsa_range, float)
            ds.attrs["avgsa_rule"] = su.avgsa_rule
        for i, d in enumerate(dims):
            ds.dims[i].attach_scale(scales[d])


def coord_attrs(axis, kind: str = "flexible") -> dict[str, Any]:
    """The attributes of an axis's coordinate in a file of a ``kind`` body."""
    return {**fields.axis_attrs(axis.name, kind), "scene_key": axis.key}


RECORD_GROUP = "record"  # a record sweep's copy of its record: file (bytes), acceleration
VERTICAL_GROUP = "vertical"  # its vertical component's copy (ground.vertical): file (bytes)
SUITE_GROUP = "records"  # a suite sweep's copies of its records' files: 0, 1, ... (bytes)


def _store_file(g, name: str, record):
    """One record's file bytes (uint8, gzip) as dataset ``name`` of group ``g``, with its
    SHA-256 and the path the sweep read it from; None for a record without bytes."""
    raw = np.frombuffer(record.data, dtype=np.uint8)
    if not raw.size:
        return None
    d = g.create_dataset(name, data=raw, chunks=(min(raw.size, 1 << 16),),
                         compression="gzip")
    d.attrs["sha256"] = record.sha256
    d.attrs["source"] = str(record.source)
    return d


def _store_suite_records(f, suite) -> None:
    """Keep a suite's records in the result file (group ``records``, dataset ``i`` for the
    i-th record: its file's bytes, SHA-256, path read and file name), as a single record's
    file keeps its record: the scene is rebuilt from them (IDA, spectra, ``--rtol``) after
    the record folder moved or is gone."""
    g = f.create_group(SUITE_GROUP)
    for i, (name, rec) in enumerate(zip(suite.names, suite.records, strict=True)):
        d = _store_file(g, str(i), rec)
        if d is not None:
            d.attrs["name"] = name


def _store_record(f, role: str, record) -> None:
    """Keep a ground file of the scene in the result file (group ``role``: RECORD_GROUP,
    VERTICAL_GROUP): the file's bytes (``file``, uint8; the scene is rebuilt from them,
    ``result_scene``), and the record's samples (``acceleration`` [g], at ``dt`` [s]) for
    readers. A result then stands alone: moved to another machine, or kept after the
    record's folder is gone, it still plots and gives boundaries and spectra."""
    g = f.create_group(role)
    _store_file(g, "file", record)
    if role != RECORD_GROUP:
        return
    acc = g.create_dataset("acceleration", data=np.asarray(record.acc, np.float64))
    acc.attrs["units"] = "g"
    acc.attrs["dt"] = float(record.dt)
