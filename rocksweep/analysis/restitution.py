"""The coefficient of restitution of eq. (1) over lam and u/u_cr for a scene's body
(Figure 2; the library side of ``rocksweep restitution``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.physics.model import Body, FlexibleBody, restitution, restitution_rigid

if TYPE_CHECKING:

    from rocksweep.scene.scene import Scene


@dataclass
class RestitutionTable:
    """e(lam, u/u_cr) of eq. (1) for one body, both transition directions.

    lam: float64[n_lam] in [0, 1]; u_over_ucr: float64[n_u] in [-2, 2]; e_upper,
    e_lower: float64[n_lam, n_u], the paper's upper sign (rocksweep: rocking on the +b
    corner ends, u positive toward +b) and the lower sign; e_housner: Housner's e of the
    same body welded rigid (lam = 0). A rigid body has no lateral displacement: its e
    depends on lam only and is repeated along u.
    """

    title: str
    body: Body
    lam: np.ndarray
    u_over_ucr: np.ndarray
    e_upper: np.ndarray
    e_lower: np.ndarray
    e_housner: float

    @property
    def e_at_rest(self) -> float:
        """e at lam = 0 and the u/u_cr value nearest 0 (upper sign)."""
        return float(self.e_upper[int(np.argmin(abs(self.lam))),
                                  int(np.argmin(abs(self.u_over_ucr)))])

    def as_dict(self) -> dict:
        """Plain JSON (the output of ``rocksweep restitution --json``)."""
        return {"lam": self.lam.tolist(), "u_over_ucr": self.u_over_ucr.tolist(),
                "e": {"upper": self.e_upper.tolist(), "lower": self.e_lower.tolist()},
                "e_housner_rigid": self.e_housner}


# Values of a restitution table (n_lam x n_u) at most: ~16 float64 temporaries of the
# table's size are alive while eq. (1) is evaluated (a few hundred MB at this bound); a
# figure needs a few thousand.
MAX_TABLE = 2_000_000


def restitution_table(scene: Scene, n_lam: int = 101, n_u: int = 81) -> RestitutionTable:
    """eq. (1) for the scene's body over lam in [0, 1] (n_lam values) and u/u_cr in
    [-2, 2] (n_u values). The scene must hold one body (a SceneError names a swept body
    key otherwise); its impact and pulse sections are not used."""
    from rocksweep.scene.scene import SceneError

    for a in scene.body_axes():
        if len(a.values) != 1:
            raise SceneError(f"{a.key} has {len(a.values)} values: restitution needs one "
                             f"body; pick one with --set {a.key}=VALUE")
    for name, n in (("n_lam", n_lam), ("n_u", n_u)):
        if n < 2:
            raise SceneError(f"{name} = {n}: must be >= 2")
    if n_lam * n_u > MAX_TABLE:
        raise SceneError(f"n_lam x n_u = {n_lam} x {n_u} = {n_lam * n_u:,} values: at most "
                         f"{MAX_TABLE:,} (a table of that many takes ~"
                         f"{16 * 8 * n_lam * n_u / 2**30:.1f} GiB to compute); use fewer")
    body = scene.make_body(**{a.name: a.values[0] for a in scene.body_axes()})
    lam = np.linspace(0.0, 1.0, n_lam)
    u_over_ucr = np.linspace(-2.0, 2.0, n_u)
    if isinstance(body, FlexibleBody) and not body.rigid:
        u = u_over_ucr * body.u_cr
        e_up = restitution(body, lam[:, None], u[None, :], upper=True)
        e_low = restitution(body, lam[:, None], u[None, :], upper=False)
    else:  # rigid: no lateral displacement, e depends on lam only
        e_up = np.repeat(restitution_rigid(body, lam)[:, None], n_u, axis=1)
        e_low = e_up.copy()
    return RestitutionTable(scene.name, body, lam, u_over_ucr, np.asarray(e_up, float),
                            np.asarray(e_low, float), float(restitution_rigid(body, 0.0)))
