"""A sweep's identity: what decides its results (``resolved_scene``, stored in every
result file as ``scene_resolved``), and the differences a resume refuses
(``scene_differences``: one phrase each, in the scene's words)."""

from __future__ import annotations

import math

from rocksweep.physics.ground_motion import vertical_ims
from rocksweep.scene.model import Scene
from rocksweep.vocab.laws import DEFAULT_LAW


def resolved_scene(scene: Scene, overrides: tuple[str, ...] | list[str] = (),
                   adaptive: dict | None = None) -> dict:
    """What decides a sweep's results (plus its name): the basis of resume checks.
    adaptive: the resolved settings of an adaptive sweep (``adaptive.Options.resolved``),
    None for a sweep of every point (then no ``adaptive`` key)."""
    d = {
        "name": scene.name,
        "kind": scene.kind,
        "axes": {a.key: {"values": list(a.values), "swept": a.swept} for a in scene.axes},
        "numerics": scene.numerics.as_dict(),
        "energy": scene.energy,
        "overrides": list(overrides),
        # only when asked: files without contact outputs keep their resolved scene
        **({"contact": True} if scene.contact else {}),
        **({"check": True} if scene.check else {}),
        **files_resolved(scene),
        **({"suite": suite_attrs(scene.suite)} if scene.suite is not None else {}),
        **({"path": path_resolved(scene)} if scene.path is not None else {}),
    }
    if adaptive is not None:
        d["adaptive"] = dict(adaptive)
    return d


def path_resolved(scene: Scene) -> dict:
    """A scene's excitation path as the resolved scene states it: the second horizontal
    components (name, SHA-256, path read; None where a record has none), the floor's
    modes given as a list (None: the one-mode axes) and whether there is a floor, and the
    pulse's p [rad/s]."""
    pa = scene.path
    return {"h2": [None if r is None else {"name": r.name, "sha256": r.sha256,
                                           "source": str(r.source)} for r in pa.h2],
            "floor": pa.floor, "p": pa.p,
            "modes": None if pa.modes is None else [
                [m.period, m.damping, m.participation] for m in pa.modes]}


def _adaptive_words(a: dict) -> str:
    """Adaptive settings as words: ``axes w_over_p,A_ratio, coarse 4, ...``."""
    return ", ".join(f"{k} {','.join(map(str, v)) if k == 'axes' else v}"
                     for k, v in a.items())


def record_attrs(record) -> dict:
    """A record scene's record as the file states it (``record_*`` attributes): name,
    SHA-256 of the file's bytes, NPTS, DT [s], PGA [g], title and the path read."""
    return {"name": record.name, "sha256": record.sha256, "npts": int(record.npts),
            "dt": float(record.dt), "pga": float(record.pga), "title": record.title,
            "source": str(record.source)}


def files_resolved(scene: Scene) -> dict[str, dict]:
    """The files of the scene's one ground record as the file states them (the resolved
    scene's keys and the attributes' prefixes, by role: ``Scene.ground_files``): each
    file's ``record_attrs``; a component beside the record with its IMs, PGA_v [g] and
    the V/H ratio (``ground_motion.vertical_ims``)."""
    files = scene.ground_files()
    return {role: record_attrs(r) if role == "record" else
            {**record_attrs(r), **vertical_ims(r, files["record"])}
            for role, r in files.items()}


def suite_attrs(suite) -> dict:
    """A suite scene's records and scaling as the resolved scene states them: the stripe
    IM (None: a cloud), Sa's period [s], the cloud's factor, the stored Sa periods [s] and
    every record's file name, SHA-256 and the path read (a resume compares names and
    SHA-256s: the files' bytes, wherever they are)."""
    def num(v: float):
        return None if math.isnan(v) else float(v)

    return {"im": suite.im, "period": num(suite.period), "factor": num(suite.factor),
            "periods": list(suite.periods),
            # multi-component records (a PEER folder): the scaling component, each
            # record's H2 and vertical (name, SHA-256); only when there are some
            **({"component": suite.component,
                "h2": [{"name": r.name, "sha256": r.sha256} for r in suite.h2],
                "vertical": [None if r is None else {"name": r.name, "sha256": r.sha256}
                             for r in suite.vertical]} if suite.h2 else {}),
            # whether the verticals act on the body (ground.vertical: true|false); only
            # stated when it is true (files before it was: the verticals did not act)
            **({"vertical_acts": True} if suite.vertical_acts else {}),
            "records": [{"name": n, "sha256": r.sha256, "source": str(r.source)}
                        for n, r in zip(suite.names, suite.records, strict=True)]}


def _suite_differences(ss: dict, sn: dict) -> list[str]:
    """One phrase per difference between two ``suite_attrs`` dicts (records by name)."""
    diffs = []
    if bool(ss.get("vertical_acts")) != bool(sn.get("vertical_acts")):
        diffs.append(f"ground.vertical: the file's records' verticals "
                     f"{'act' if ss.get('vertical_acts') else 'do not act'} on the body, "
                     f"the scene's {'do' if sn.get('vertical_acts') else 'do not'}")
    for k in ("im", "period", "factor", "periods", "component", "h2", "vertical"):
        if ss.get(k) != sn.get(k):
            diffs.append(f"ground.scale {k}: file {ss.get(k)!r}, scene {sn.get(k)!r}"
                         if k != "periods" else
                         f"ground.periods: file {ss.get(k)!r}, scene {sn.get(k)!r}")
    new = {r.get("name"): r for r in sn.get("records") or []}
    for r in ss.get("records") or []:
        m = new.get(r.get("name"))
        if m is not None and m.get("sha256") != r.get("sha256"):
            diffs.append(f"ground.records: {r.get('name')} changed since the sweep (sha256 "
                         f"{str(r.get('sha256'))[:12]} in the file, {str(m.get('sha256'))[:12]}"
                         f" now, read from {m.get('source')})")
    return diffs


def _short(v) -> str:
    if isinstance(v, dict) and "values" in v:
        vals = v["values"]
        text = (repr(vals[0]) if not v["swept"] else
                f"[{', '.join(map(repr, vals))}]" if len(vals) <= 6 else
                f"{len(vals)} values {vals[0]!r}..{vals[-1]!r}")
        return text
    return repr(v)


# Axes a scene need not give, with the value they then have: the impact law's (eq. 1)
AXIS_DEFAULTS = {"impact.law": DEFAULT_LAW, "impact.e_factor": 1.0}


def scene_differences(stored: dict, new: dict) -> list[str]:
    """One phrase per difference between two ``resolved_scene`` dicts."""
    diffs = []
    outputs = ("energy", "contact", "check")  # absent: false
    for section in ("name", "kind", *outputs):  # --set overrides show in the axes
        a, b = stored.get(section), new.get(section)
        if section in outputs:
            a, b = str(bool(a)).lower(), str(bool(b)).lower()
        if a != b:
            key = f"outputs.{section}" if section in outputs else section
            diffs.append(f"{key}: file {a if section in outputs else _short(a)}, "
                         f"scene {b if section in outputs else _short(b)}")
    for key in dict.fromkeys([*stored.get("axes", {}), *new.get("axes", {})]):
        a, b = stored.get("axes", {}).get(key), new.get("axes", {}).get(key)
        if key in AXIS_DEFAULTS:  # a key not given is its default (files before it existed)
            a = a or {"values": [AXIS_DEFAULTS[key]], "swept": False}
            b = b or {"values": [AXIS_DEFAULTS[key]], "swept": False}
        if a != b:
            diffs.append(f"{key}: file {_short(a) if a else 'absent'}, "
                         f"scene {_short(b) if b else 'absent'}")
    rs, rn = stored.get("record") or {}, new.get("record") or {}
    if rs.get("sha256") != rn.get("sha256"):  # the record's bytes, wherever the file is
        diffs.append(f"ground.record: file {rs.get('name', 'absent')} (sha256 "
                     f"{str(rs.get('sha256'))[:12]}), scene {rn.get('name', 'absent')} "
                     f"(sha256 {str(rn.get('sha256'))[:12]})")
    if stored.get("suite") is not None or new.get("suite") is not None:
        if stored.get("suite") is None or new.get("suite") is None:
            diffs.append("ground.records: file " + ("a suite" if stored.get("suite") else
                                                    "no suite") + ", scene " +
                         ("a suite" if new.get("suite") else "no suite"))
        else:
            diffs += _suite_differences(stored["suite"], new["suite"])
    ps, pn = stored.get("path") or {}, new.get("path") or {}
    for k in ("floor", "modes", "p"):
        if ps.get(k) != pn.get(k):
            diffs.append(f"floor ({k}): file {_short(ps.get(k))}, scene {_short(pn.get(k))}")
    if [h and h.get("sha256") for h in ps.get("h2") or []] != [
            h and h.get("sha256") for h in pn.get("h2") or []]:
        diffs.append("ground.h2: the second horizontal components differ (sha256)")
    sn, nn = stored.get("numerics", {}), new.get("numerics", {})
    for key in dict.fromkeys([*sn, *nn]):
        if sn.get(key) != nn.get(key):
            diffs.append(f"numerics.{key}: file {sn.get(key)!r}, scene {nn.get(key)!r}")
    sa, na = stored.get("adaptive"), new.get("adaptive")
    if sa is not None and na is None:
        diffs.append(f"adaptive: file adaptive ({_adaptive_words(sa)}), this run not")
    elif sa is None and na is not None:
        diffs.append("adaptive: file of every point, this run adaptive")
    elif sa != na:
        for key in dict.fromkeys([*sa, *na]):
            if sa.get(key) != na.get(key):
                diffs.append(f"adaptive.{key}: file {sa.get(key)!r}, this run "
                             f"{na.get(key)!r}")
    return diffs
