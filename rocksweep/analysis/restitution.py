"""The coefficient of restitution of eq. (1) over lam and u/u_cr for a scene's body
(Figure 2; the library side of ``rocksweep restitution``)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.errors import Arg, SceneError, set_key
from rocksweep.physics.bodies import Body, FlexibleBody, restitution_rigid
from rocksweep.physics.impact import U_RANGE, body_lam_limit, lam_energy_limit
from rocksweep.physics.impact import restitution as law_restitution

if TYPE_CHECKING:

    from rocksweep.scene.model import Scene


@dataclass
class RestitutionTable:
    """e(lam, u/u_cr) of eq. (1) for one body, both transition directions.

    lam: float64[n_lam] in [0, 1]; u_over_ucr: float64[n_u] in [-2, 2]; e_upper,
    e_lower: float64[n_lam, n_u], the paper's upper sign (rocksweep: rocking on the +b
    corner ends, u positive toward +b) and the lower sign; e_housner: Housner's e of the
    same body welded rigid (lam = 0). A rigid body has no lateral displacement: its e
    depends on lam only and is repeated along u. law, e, e_factor: the impact law
    (``rocksweep.physics.impact``; eq. 1 is ``vertical``); lam_limit: float64[n_u], the
    largest lam in [0, 2] at which an impact (upper sign) cannot gain energy (2: none up
    to 2 does, NaN: every lam does; ``locked`` with u' = 0).
    """

    title: str
    body: Body
    lam: np.ndarray
    u_over_ucr: np.ndarray
    e_upper: np.ndarray
    e_lower: np.ndarray
    e_housner: float
    law: str = "vertical"
    e: float = math.nan
    e_factor: float = 1.0
    lam_limit: np.ndarray | None = None

    @property
    def e_at_rest(self) -> float:
        """e at lam = 0 and the u/u_cr value nearest 0 (upper sign)."""
        return float(self.e_upper[int(np.argmin(abs(self.lam))),
                                  int(np.argmin(abs(self.u_over_ucr)))])

    def as_dict(self) -> dict:
        """Plain JSON (the output of ``rocksweep restitution --json``)."""
        lim = [None if math.isnan(v) else v for v in self.lam_limit.tolist()]
        return {"lam": self.lam.tolist(), "u_over_ucr": self.u_over_ucr.tolist(),
                "law": self.law, "e_constant": None if math.isnan(self.e) else self.e,
                "e_factor": self.e_factor,
                "e": {"upper": self.e_upper.tolist(), "lower": self.e_lower.tolist()},
                "e_housner_rigid": self.e_housner, "lam_energy_limit": lim}


# Values of a restitution table (n_lam x n_u) at most: ~16 float64 temporaries of the
# table's size are alive while eq. (1) is evaluated (a few hundred MB at this bound); a
# figure needs a few thousand.
MAX_TABLE = 2_000_000


def restitution_table(scene: Scene, n_lam: int = 101, n_u: int = 81) -> RestitutionTable:
    """e of the scene's impact law (eq. 1 unless ``impact.law`` says otherwise) for the
    scene's body over lam in [0, 1] (n_lam values) and u/u_cr in [-2, 2] (n_u values),
    with the energy-admissible lam for each u/u_cr. The scene must hold one body and one
    impact law (a SceneError names a swept key otherwise); lam and the pulse are not used.
    """
    names = [a.name for a in scene.axes]
    for a in (*scene.body_axes(), *(scene.axis(k) for k in ("law", "e", "e_factor")
                                    if k in names)):
        if len(a.values) != 1:
            what = "one body" if a.key.startswith("body.") else "one impact law"
            raise SceneError(f"{a.key} has {len(a.values)} values: restitution needs {what}; "
                             "pick one with {fix}" + (" or {law}" if a.key == "impact.law"
                                                      else ""),
                             fix=set_key(a.key, "set_fix"), law=Arg("law"))
    for name, n in (("n_lam", n_lam), ("n_u", n_u)):
        if n < 2:
            raise SceneError(f"{name} = {n}: must be >= 2")
    if n_lam * n_u > MAX_TABLE:
        raise SceneError(f"n_lam x n_u = {n_lam} x {n_u} = {n_lam * n_u:,} values: at most "
                         f"{MAX_TABLE:,} (a table of that many takes ~"
                         f"{16 * 8 * n_lam * n_u / 2**30:.1f} GiB to compute); use fewer")
    body = scene.make_body(**{a.name: a.values[0] for a in scene.body_axes()})
    law = scene.axis("law").values[0] if "law" in names else "vertical"
    e = float(scene.axis("e").values[0]) if "e" in names else math.nan
    f = float(scene.axis("e_factor").values[0]) if "e_factor" in names else 1.0
    lam = np.linspace(0.0, 1.0, n_lam)
    u_over_ucr = np.linspace(-2.0, 2.0, n_u)
    if isinstance(body, FlexibleBody) and not body.rigid:
        u = u_over_ucr * body.u_cr
    else:  # rigid: no lateral displacement, e depends on lam only
        u = np.zeros(n_u)
    e_up = law_restitution(body, lam[:, None], u[None, :], True, law, e, f)
    e_low = law_restitution(body, lam[:, None], u[None, :], False, law, e, f)
    lim = lam_energy_limit(body, u, True, law, e, f)
    return RestitutionTable(scene.name, body, lam, u_over_ucr, np.asarray(e_up, float),
                            np.asarray(e_low, float), float(restitution_rigid(body, 0.0)),
                            law, e, f, np.asarray(lim, float))


def energy_note(scene: Scene, max_bodies: int = 64) -> str | None:
    """One line when the scene's largest lam exceeds the body's energy-admissible lam
    under one of its impact laws (``rocksweep.physics.impact.body_lam_limit``: above it
    some impact with |u/u_cr| <= 2 gains energy, which the paper says to avoid), else
    None. Not an error: such runs are flagged energy_gain where it happens. Scenes with
    more than ``max_bodies`` bodies are not checked."""
    axes = scene.body_axes()
    if math.prod(len(a.values) for a in axes) > max_bodies:
        return None
    lam = max(scene.axis("lam").values)
    names = [a.name for a in scene.axes]
    laws = scene.axis("law").values if "law" in names else ("vertical",)
    es = scene.axis("e").values if "e" in names else (math.nan,)
    factors = scene.axis("e_factor").values if "e_factor" in names else (1.0,)
    worst: dict[str, float] = {}
    for combo in product(*(a.values for a in axes)):
        body = scene.make_body(**{a.name: v for a, v in zip(axes, combo, strict=True)})
        for law, f in product(laws, factors):
            for e in (es if law == "constant" else (math.nan,)):
                lim = body_lam_limit(body, law, e, f)
                key = law if len(factors) == 1 else f"{law} (e_factor {f:g})"
                worst[key] = min(worst.get(key, math.inf), lim if lim == lim else -1.0)
    over = {k: v for k, v in worst.items() if lam > v}
    if not over:
        return None
    parts = [f"{k} {v:.3g}" if v >= 0 else f"{k}: at every lam" for k, v in over.items()]
    return (f"note: lam = {lam:g} exceeds the largest lam at which no impact of this body "
            f"with |u/u_cr| <= {U_RANGE:g} can gain energy ({', '.join(parts)}; see "
            "the restitution table of each law)")
