"""What a sweep result holds: class counts per swept key, completeness and provenance
(the library side of ``rocksweep info`` and of the summary ``rocksweep sweep`` prints).

Counts are per class (mode 1 / mode 2 / safe), with the points flagged (horizon, step or
event cap, non-finite state) and not computed yet. ``class_counts`` groups them by any
swept keys, summing over the others; long axes are shown as ranges of values
(``in_ranges``), so a 101-value lam axis takes a few lines, not a hundred.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.compute.adaptive import stats_of
from rocksweep.fields import THETA_REL_FLOOR, plain
from rocksweep.store.reader import read_result, stored_scene
from rocksweep.vocab.axes import axis_name
from rocksweep.vocab.outcomes import (
    COMPUTED,
    FILLED,
    FLAGGED,
    LIFTS_OFF,
    MODE1,
    MODE2,
    OUTCOME_CODE,
    OUTCOME_NOT_RUN,
    OUTCOME_SAFE,
    SAFE,
    SLID,
    SLIDES,
    STATUS_BIT,
)

if TYPE_CHECKING:
    from rocksweep.store.reader import SweepResult

CLASSES = (MODE1, MODE2, SAFE, "flagged", "not_computed")
# Counted too in results with contact outputs (outputs.contact / body.mu): computed points
# whose status says the base would slide (mu_required > body.mu) or lift off (N < 0).
CONTACT_COUNTS = (SLIDES, LIFTS_OFF)
# ... and in results of a scene that gives body.mu (the sliding base, docs/sliding.md):
# computed points whose base slipped, or met a normal force below zero while rocking
SLIDE_COUNTS = (SLID, LIFTS_OFF)
EXTRA_COUNTS = (SLIDES, SLID, LIFTS_OFF)
# A swept key with more values than this is printed as this many ranges of values.
MAX_ROWS = 10
# Variables ``info_dict`` needs from the file (and ``computed`` when the file has it:
# ``read_result(path, INFO_VARIABLES, optional=INFO_OPTIONAL)``).
INFO_VARIABLES = ["outcome", "status", "steps", "event_steps"]
INFO_OPTIONAL = ("computed",)
# ... and, in files with per-point error estimates (outputs.check), these.
CHECK_INFO_VARIABLES = ["theta_max_over_alpha", "check_outcome", "check_t_overturn_diff",
                        "check_theta_max_diff"]


def class_counts(result: SweepResult, by: Sequence[str]) -> list[dict]:
    """Points per class for each combination of values of the swept keys ``by`` (in the
    grid's order, the others summed); keys in ``by`` that are not swept are labelled with
    their one value.

    Returns one dict per combination: the key values, then mode1, mode2, safe, flagged
    (computed points with a flagged status) and not_computed; with contact outputs also
    slides and lifts_off (``CONTACT_COUNTS``), where the base slides slid and lifts_off
    (``SLIDE_COUNTS``).
    """
    out = np.asarray(result.arrays["outcome"])
    status = np.asarray(result.arrays["status"])
    swept = [d for d in by if d in result.dims]
    pos = [result.dims.index(d) for d in swept]
    rest = [i for i in range(len(result.dims)) if i not in pos]
    shape = [result.shape[i] for i in pos]
    o = np.transpose(out, [*pos, *rest]).reshape(*shape, -1)
    fl = np.transpose((status & FLAGGED) != 0, [*pos, *rest]).reshape(o.shape)
    fl &= o != OUTCOME_NOT_RUN
    scene = getattr(result, "scene", {})
    counts = (CONTACT_COUNTS if scene.get("contact") else
              SLIDE_COUNTS if "body.mu" in (scene.get("axes") or {}) else ())
    extra = {c: np.transpose((status & STATUS_BIT[c]) != 0, [*pos, *rest]).reshape(o.shape)
             & (o != OUTCOME_NOT_RUN) for c in counts}
    rows = []
    for idx in np.ndindex(*shape):
        label = {d: (plain(result.coords[d][idx[swept.index(d)]]) if d in swept
                     else plain(result.scalars.get(d))) for d in by}
        cell = o[idx]
        rows.append({**label,
                     **{w: int((cell == OUTCOME_CODE[w]).sum()) for w in CLASSES[:3]},
                     "flagged": int(fl[idx].sum()),
                     "not_computed": int((cell == OUTCOME_NOT_RUN).sum()),
                     **{c: int(v[idx].sum()) for c, v in extra.items()}})
    return rows


def counts_by_key(result: SweepResult) -> dict[str, list[dict]]:
    """swept key -> ``class_counts`` over its values alone (every other key summed)."""
    return {d: class_counts(result, [d]) for d in result.dims}


def shape_lam_counts(result: SweepResult) -> list[dict]:
    """Counts per pulse shape and lam (the paper's comparison of Figures 3 and 4), and per
    impact law when the law is swept (``impact.law``)."""
    return class_counts(result, ["shape", *(["law"] if "law" in result.dims else []), "lam"])


def in_ranges(rows: list[dict], key: str, max_rows: int = MAX_ROWS) -> list[dict]:
    """Consecutive rows that share every label but ``key`` merged into at most
    ``max_rows`` ranges of ``key``'s values, counts summed; a merged row's ``key`` is
    (first, last) and ``n_values`` says how many values it holds."""
    labels = [k for k in rows[0] if k not in (*CLASSES, *EXTRA_COUNTS)] if rows else []
    counted = [c for c in (*CLASSES, *EXTRA_COUNTS) if rows and c in rows[0]]
    others = [k for k in labels if k != key]
    out: list[dict] = []
    start = 0
    while start < len(rows):
        stop = start
        while stop < len(rows) and all(rows[stop][k] == rows[start][k] for k in others):
            stop += 1
        run = rows[start:stop]
        if len(run) <= max_rows:
            out.extend(run)
        else:
            for part in np.array_split(np.arange(len(run)), max_rows):
                group = [run[i] for i in part]
                row = {k: group[0][k] for k in others}
                row[key] = (group[0][key], group[-1][key])
                row["n_values"] = len(group)
                row.update({c: sum(g[c] for g in group) for c in counted})
                out.append(row)
        start = stop
    return out


def _label(v) -> str:
    if isinstance(v, tuple):
        return f"{_label(v[0])} .. {_label(v[1])}"
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)


def format_counts(rows: list[dict], indent: str = "") -> list[str]:
    """A text table of ``class_counts`` rows (ranges from ``in_ranges`` as "a .. b");
    the not_computed column only when some point is missing."""
    if not rows:
        return []
    labels = [k for k in rows[0] if k not in (*CLASSES, *EXTRA_COUNTS) and k != "n_values"]
    classes = [c for c in CLASSES if c != "not_computed" or any(r[c] for r in rows)]
    classes += [c for c in EXTRA_COUNTS if c in rows[0]]
    cells = [[_label(r[k]) for k in labels] for r in rows]
    widths = [max(len(k), *(len(c[i]) for c in cells)) for i, k in enumerate(labels)]
    head = "".join(f"{k:<{w + 2}}" for k, w in zip(labels, widths, strict=True))
    names = {"not_computed": "missing"}
    cw = {c: max(9, len(names.get(c, c)) + 1) for c in classes}
    lines = [indent + head + "".join(f"{names.get(c, c):>{cw[c]}}" for c in classes)]
    for r, c in zip(rows, cells, strict=True):
        left = "".join(f"{v:<{w + 2}}" for v, w in zip(c, widths, strict=True))
        lines.append(indent + left + "".join(f"{r[k]:>{cw[k]}}" for k in classes))
    return lines


def counts_lines(result: SweepResult) -> list[str]:
    """The per shape and lam table, long lam axes in ranges (``rocksweep sweep`` prints
    it after a sweep)."""
    return format_counts(in_ranges(shape_lam_counts(result), "lam"))


def _json_value(v):
    """JSON has no inf: write it as the string "inf" (wn_over_p: .inf, a rigid body)."""
    if isinstance(v, float) and math.isinf(v):
        return "inf" if v > 0 else "-inf"
    if isinstance(v, float) and math.isnan(v):
        return None
    return v


def read_info(path) -> SweepResult:
    """The variables of a result file that ``info_dict`` reports on."""
    check = bool(stored_scene(path).get("check"))
    return read_result(path, INFO_VARIABLES + (CHECK_INFO_VARIABLES if check else []),
                       INFO_OPTIONAL)


def _tail(x: np.ndarray) -> dict:
    """Median, 95th percentile and maximum of the finite values of x (None if none)."""
    x = x[np.isfinite(x)]
    if not x.size:
        return {"n": 0, "median": None, "p95": None, "max": None}
    return {"n": int(x.size), "median": float(np.median(x)),
            "p95": float(np.percentile(x, 95)), "max": float(x.max())}


def check_info(result: SweepResult) -> dict | None:
    """The per-point error estimates of a result with ``outputs.check`` (None without):
    points whose outcome changes at half the step, and the tails (median, 95th
    percentile, max) of |t_overturn change| [p*t] where both runs overturn and of the
    relative |max|theta| change| of safe runs (both safe, theta_max >= THETA_REL_FLOOR)."""
    if not result.scene.get("check") or "check_outcome" not in result.arrays:
        return None
    a = result.arrays
    out, chk = np.asarray(a["outcome"]), np.asarray(a["check_outcome"])
    run = out != OUTCOME_NOT_RUN
    theta = np.asarray(a["theta_max_over_alpha"])
    safe = run & (out == OUTCOME_SAFE) & (chk == OUTCOME_SAFE) & (theta >= THETA_REL_FLOOR)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.abs(np.asarray(a["check_theta_max_diff"])[safe]) / theta[safe]
    return {"points": int(run.sum()),
            "outcome_changes": int((run & (chk != out)).sum()),
            "t_overturn_diff": _tail(np.abs(np.asarray(a["check_t_overturn_diff"])[run])),
            "theta_max_rel_diff": _tail(rel)}


def info_dict(result: SweepResult) -> dict:
    """Everything ``rocksweep info`` reports, as plain JSON: dims (size, scene key,
    values), fixed keys, completeness, counts per shape and lam and per swept key,
    accuracy, RK4 step totals and provenance (versions, times, overrides, scene YAML).

    result: ``read_info(path)``.
    """
    a = result.attrs
    done = result.done
    keys = {axis_name(k): k for k in result.scene["axes"]}
    dims = {d: {"size": len(result.coords[d]), "scene_key": keys[d],
                "values": [plain(v) for v in result.coords[d]]} for d in result.dims}
    return {
        "path": str(result.path),
        "title": result.name,
        "format_version": a.get("format_version"),
        "body_kind": result.kind,
        "p": _json_value(float(a["p"])) if "p" in a else None,  # a physical body's [rad/s]
        "dims": dims,
        "fixed": {k: _json_value(v) for k, v in result.scalars.items()},
        "points_total": int(done.size),
        "points_done": int(done.sum()),
        "complete": bool(done.all()),
        "counts": shape_lam_counts(result),
        "counts_by_key": counts_by_key(result),
        "accuracy": a.get("accuracy"),
        "numerics": json.loads(a.get("numerics", "{}")),
        "energy": bool(a.get("energy", False)),
        "steps_total": int(result.arrays["steps"].sum()),
        "event_steps_total": int(result.arrays["event_steps"].sum()),
        "certification": certification_info(result),
        "provenance": {
            **{k: a.get(k) for k in ("rocksweep_version", "numba_version", "numpy_version",
                                     "h5py_version", "hdf5_version", "python_version",
                                     "started", "finished", "sessions")},
            "wall_time_s": a.get("wall_time"),
            "cpu_time_s": a.get("cpu_time"),
            "overrides": json.loads(a.get("overrides", "[]")),
        },
        "adaptive": adaptive_info(result),
        "check": check_info(result),
        "vertical": vertical_info(result),
        "scene": a.get("scene"),
    }


def certification_info(result: SweepResult) -> dict:
    """What the certification of close calls cost (``compute.certify``): points_refined
    (status ``refined``: checked or re-run finer), points_uncertified, and
    refine_evaluations, the RK4 evaluations (regular + event) of its runs, part of the
    steps totals (None where not recorded: a file of a rocksweep before the count)."""
    status = np.asarray(result.arrays["status"])
    n = int(result.attrs.get("refine_evaluations", -1))
    return {"points_refined": int(((status & STATUS_BIT["refined"]) != 0).sum()),
            "points_uncertified": int(((status & STATUS_BIT["uncertified"]) != 0).sum()),
            "refine_evaluations": n if n >= 0 else None}


def vertical_info(result: SweepResult) -> dict:
    """Whether a vertical ground acceleration acted on the body, from the resolved scene:
    {"acted": bool, "source": "ground.vertical" | "pulse.vertical" | "up files" | None,
    "words": one line}. A folder suite's UP files read but not acting (``ground.vertical:
    false``) say so: their peaks are stored, the body did not feel them."""
    sc = result.scene
    rec = sc.get("vertical")
    if isinstance(rec, dict):
        peak = rec.get("PGA_v")
        return {"acted": True, "source": "ground.vertical",
                "words": f"acted: ground.vertical {rec.get('name')} (PGA_v "
                         f"{peak if peak is None else f'{peak:.4g}'} g as recorded, scaled with "
                         "the record), the kernel's vertical variant"}
    amp = (sc.get("axes") or {}).get("pulse.vertical.amplitude")
    if isinstance(amp, dict):
        acted = any(isinstance(v, int | float) and v != 0 for v in amp.get("values") or [])
        return {"acted": acted, "source": "pulse.vertical",
                "words": ("acted: pulse.vertical (a harmonic), the kernel's vertical variant"
                          if acted else "none: pulse.vertical's amplitude is 0")}
    suite = sc.get("suite") if isinstance(sc.get("suite"), dict) else {}
    ups = [v for v in suite.get("vertical") or [] if v]
    if ups:
        acts = bool(suite.get("vertical_acts"))
        return {"acted": acts, "source": "up files",
                "words": (f"acted: the {len(ups)} records' UP files, scaled with each record "
                          "(the kernel's vertical variant)" if acts else
                          f"did not act: the {len(ups)} records' UP files were read "
                          "(record_pga_v, record_v_over_h) but ground.vertical: false kept "
                          "them off the body")}
    return {"acted": False, "source": None, "words": "none (gravity alone)"}


def adaptive_info(result: SweepResult) -> dict | None:
    """The settings and counts of an adaptive sweep (None for a sweep of every point):
    settings as recorded (axes, coarse, margin, final_margin, audit, seed, threshold);
    computed, filled (outcome from the cell around the point), undecided (neither yet: an
    unfinished sweep), audited, audit_misses, from the ``computed`` flags."""
    settings = result.scene.get("adaptive")
    if not settings or "computed" not in result.arrays:
        return None
    c = np.asarray(result.arrays["computed"])
    st = stats_of(c, settings.get("threshold", 0.0))
    filled = int(((c == 0) & result.done).sum())
    return {"settings": settings, "points": st.points, COMPUTED: st.computed,
            FILLED: filled, "undecided": st.points - st.computed - filled,
            "audited": st.audited, "audit_misses": st.audit_misses,
            "warning": st.warning()}


def format_check(ck: dict) -> list[str]:
    """The lines of ``rocksweep info`` on a result's error estimates (``check_info``)."""
    def tail(t: dict, unit: str) -> str:
        if not t["n"]:
            return "no such points"
        return (f"median {t['median']:.2g}, 95% {t['p95']:.2g}, max {t['max']:.2g}{unit} "
                f"({t['n']} points)")

    n = max(1, ck["points"])
    return [f"error estimates (each point rerun at half the step, outputs.check): "
            f"outcome changes at {ck['outcome_changes']} of {ck['points']} points "
            f"({100 * ck['outcome_changes'] / n:.2f}%)",
            f"  |t_overturn change|: {tail(ck['t_overturn_diff'], ' p*t')}",
            f"  |max|theta| change| / max|theta| of safe runs: "
            f"{tail(ck['theta_max_rel_diff'], '')}"]


def certification_share(n: int | None, evaluations: int) -> str:
    """The certification's share of a file's RK4 evaluations (n of evaluations, regular +
    event; None or < 0: not recorded), as ``rocksweep info`` and ``sweep`` say it."""
    if n is None or n < 0:
        return "its share of the steps not recorded (written before rocksweep counted it)"
    own = evaluations - n
    ratio = f", {evaluations / own:.3f}x the points' own" if own > 0 else ""
    return f"{n} of them ({100 * n / max(1, evaluations):.1f}%{ratio})"


def format_certification(c: dict, evaluations: int) -> str:
    """The line of ``rocksweep info`` on the certification's price (``certification_info``;
    evaluations: the file's RK4 evaluations, regular + event)."""
    pts = (f"{c['points_refined']} points refined (checked or re-run finer), "
           f"{c['points_uncertified']} uncertified")
    share = certification_share(c["refine_evaluations"], evaluations)
    if c["refine_evaluations"] is None:
        return f"  certification of close calls: {pts}; {share}"
    return f"  certification of close calls: {share}; {pts}"


def format_info(d: dict) -> list[str]:
    """The text of ``rocksweep info`` from ``info_dict``."""
    lines = [f"{d['path']}: {d['title']}"]
    for name, dim in d["dims"].items():
        v = dim["values"]
        span = (", ".join(map(str, v)) if len(v) <= 6 else
                f"{v[0]} .. {v[-1]}" if isinstance(v[0], str) else f"{v[0]:g} .. {v[-1]:g}")
        lines.append(f"  {name:<10} {dim['size']:>6}  [{span}]   ({dim['scene_key']})")
    if d["fixed"]:
        lines.append("  fixed: " + ", ".join(f"{k} = {v}" for k, v in d["fixed"].items()))
    if d.get("p") is not None:
        lines.append(f"  physical body: p = {d['p']:.5g} rad/s")
    pct = 100 * d["points_done"] / max(1, d["points_total"])
    state = ("complete" if d["complete"] else
             "INCOMPLETE (a resume of its sweep finishes it)")
    lines.append(f"points: {d['points_done']} of {d['points_total']} done ({pct:.1f}%), "
                 f"{state}")
    ad = d.get("adaptive")
    if ad:
        s = ad["settings"]
        n = max(1, ad["points"])
        lines.append(f"adaptive over {' x '.join(s['axes'])} (coarse {s['coarse']}, margin "
                     f"{s['margin']}/{s['final_margin']}, audit {s['audit']:g}, seed "
                     f"{s['seed']}): {ad['computed']} computed "
                     f"({100 * ad['computed'] / n:.2f}%), {ad['filled']} filled"
                     + (f", {ad['undecided']} not decided yet" if ad["undecided"] else ""))
        lines.append(f"  audit: {ad['audited']} points, {ad['audit_misses']} disagreed with "
                     "their fill" + (f" (warning: {ad['warning']})" if ad["warning"] else ""))
    if d.get("vertical"):
        lines.append(f"vertical ground acceleration: {d['vertical']['words']}")
    law = bool(d["counts"]) and "law" in d["counts"][0]
    lines.append(f"counts per pulse shape{', impact law' if law else ''} and lam:")
    lines += format_counts(in_ranges(d["counts"], "lam"), "  ")
    ck = d.get("check")
    if ck:
        lines += format_check(ck)
    by_key = {k: rows for k, rows in d["counts_by_key"].items()
              if k not in ("shape", "lam", "law")}
    if by_key:
        lines.append("counts per swept key (the other keys summed):")
        for key, rows in by_key.items():
            lines += format_counts(in_ranges(rows, key), "  ")
    p = d["provenance"]
    lines.append(f"accuracy: {d['accuracy']}")
    lines.append(f"RK4 steps: {d['steps_total']} + {d['event_steps_total']} event "
                 "re-integrations")
    lines.append(format_certification(d["certification"],
                                      d["steps_total"] + d["event_steps_total"]))
    wall = p["wall_time_s"] or 0.0
    lines.append(f"run: started {p['started']}, finished {p['finished'] or '-'}, "
                 f"{p['sessions']} session(s), {wall:.2f} s wall time, "
                 f"{p['cpu_time_s'] or 0.0:.2f} s CPU time on the points")
    lines.append(f"versions: rocksweep {p['rocksweep_version']}, numba {p['numba_version']}, "
                 f"numpy {p['numpy_version']}, h5py {p['h5py_version']} "
                 f"(HDF5 {p['hdf5_version']}), Python {p['python_version']}")
    if p["overrides"]:
        lines.append("overrides: " + ", ".join(p["overrides"]))
    return lines
