"""The swept keys as users see them: names, units, the paper's symbols; the diagram's axes.

``AXES`` is the one table: a coordinate's stored attributes (``rocksweep.fields.axis_attrs``)
and a figure's axis labels (``label``) both read it. ``alpha_ref`` in a symbol is the body's
slenderness that normalises the amplitude: alpha_cg for a flexible body, alpha for a block.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class AxisMeta:
    """A swept key as users see it: long_name (short, no units), CF units ("1": a pure
    number, "": a word), the paper's symbol (plain text) and its LaTeX form for figures."""

    long_name: str
    units: str
    symbol: str
    latex: str


AXES: dict[str, AxisMeta] = {
    "shape": AxisMeta("pulse shape", "", "shape", "pulse"),
    "w_over_p": AxisMeta("pulse frequency ratio (Pi5)", "1", "omega/p", r"\omega/p"),
    "A_ratio": AxisMeta("pulse amplitude ratio (Pi6)", "1", "A/(g tan alpha_ref)",
                        r"A/(g\,\tan\alpha_{ref})"),
    "p": AxisMeta("frequency parameter of the body", "rad/s", "p", "p"),
    "lam": AxisMeta("impulse position ratio (Pi10)", "1", "lambda", r"\lambda"),
    "law": AxisMeta("impact law", "", "law", "impact law"),
    "e": AxisMeta("coefficient of restitution of law constant", "1", "e", "e"),
    "e_factor": AxisMeta("factor on the impact law's e", "1", "e_factor",
                         r"e_{\mathrm{factor}}"),
    "wn_over_p": AxisMeta("spring frequency ratio (Pi1)", "1", "omega_n/p", r"\omega_n/p"),
    "zeta": AxisMeta("damping ratio (Pi2)", "1", "zeta", r"\zeta"),
    "alpha_cg": AxisMeta("slenderness of the centre of gravity (Pi3)", "rad", "alpha_cg",
                         r"\alpha_{cg}"),
    "alpha_A": AxisMeta("slenderness of the base mass (Pi4)", "rad", "alpha_A",
                        r"\alpha_A"),
    "mA_over_m": AxisMeta("base to top mass ratio (Pi8)", "1", "m_A/m", "m_A/m"),
    "IA_ratio": AxisMeta("base inertia ratio (Pi9)", "1", "I_A/(m_A R_A^2)",
                         r"I_A/(m_A R_A^2)"),
    "alpha": AxisMeta("slenderness of the block", "rad", "alpha", r"\alpha"),
    "inertia": AxisMeta("inertia ratio of the block", "1", "I_O/(M R^2)", r"I_O/(M R^2)"),
    # a record suite (ground.records): the records, the stripe IMs (ground.scale.im; each
    # record scaled so that its IM equals the stripe's value) and Sa's periods
    "record": AxisMeta("ground-motion record (file name)", "", "record", "record"),
    "PGA": AxisMeta("peak ground acceleration of the scaled record", "g", "PGA", "PGA"),
    "PGV": AxisMeta("peak ground velocity of the scaled record", "m/s", "PGV", "PGV"),
    "Sa": AxisMeta("spectral acceleration of the scaled record (5% damping)", "g", "Sa(T)",
                   r"S_a(T)"),
    "PGA_ratio": AxisMeta("PGA of the scaled record over g tan(alpha_ref)", "1",
                          "PGA/(g tan alpha_ref)", r"PGA/(g\,\tan\alpha_{ref})"),
    "PGV_ratio": AxisMeta("PGV p of the scaled record over g tan(alpha_ref)", "1",
                          "PGV p/(g tan alpha_ref)", r"PGV\,p/(g\,\tan\alpha_{ref})"),
    "AvgSa": AxisMeta("AvgSa of the scaled record: geometric mean of Sa (5% damping) over "
                      "the periods avgsa_periods", "g", "AvgSa", r"S_{a,avg}"),
    "CAV": AxisMeta("cumulative absolute velocity of the scaled record", "m/s", "CAV", "CAV"),
    "Arias": AxisMeta("Arias intensity of the scaled record", "m/s", "I_A", r"I_A"),
    "period": AxisMeta("period of the oscillator of Sa (5% damping)", "s", "T", "T"),
    # the state at t = 0 (scene section ``initial``; INITIAL below)
    "theta_over_alpha": AxisMeta("initial rotation", "1", "theta_0/alpha_ref",
                                 r"\theta_0/\alpha_{ref}"),
    "thetadot_over_palpha": AxisMeta("initial rotation rate", "1",
                                     "theta'_0/(p alpha_ref)",
                                     r"\dot\theta_0/(p\,\alpha_{ref})"),
    "u_over_ucr": AxisMeta("initial displacement of the top mass", "1", "u_0/u_cr",
                           r"u_0/u_{cr}"),
    "udot_over_pucr": AxisMeta("initial velocity of the top mass", "1", "u'_0/(p u_cr)",
                               r"\dot u_0/(p\,u_{cr})"),
    "angle": AxisMeta("angle of the rocking plane to the first horizontal component",
                      "degree", "angle", r"\beta"),
    "floor.period": AxisMeta("period of the building's mode", "s", "T_b", r"T_b"),
    "floor.damping": AxisMeta("damping ratio of the building's mode", "1", "zeta_b",
                              r"\zeta_b"),
    "floor.participation": AxisMeta("participation of the building's mode at the floor",
                                    "1", "Gamma phi", r"\Gamma\phi"),
}

#: the sections whose keys name their axes in full (``floor.period``: a suite's ``period``
#: is the Sa periods' dimension); every other key's axis is its last part (``body.zeta``)
FULL_NAME_SECTIONS: tuple[str, ...] = ("floor",)


def axis_name(key: str) -> str:
    """The dimension name of a scene key: ``floor.period`` as is, ``body.zeta`` -> zeta."""
    section, _, rest = key.partition(".")
    return key if section in FULL_NAME_SECTIONS else rest

#: the initial state's keys (scene section ``initial``, each sweepable), normalised as
#: ``simulate --csv`` writes them: theta/alpha_ref, theta'/(p alpha_ref), u/u_cr, u'/(p u_cr)
INITIAL: tuple[str, ...] = ("theta_over_alpha", "thetadot_over_palpha", "u_over_ucr",
                            "udot_over_pucr")

#: the stability diagram's axes (x, y): the paper's omega/p and A/(g tan alpha_ref)
DIAGRAM_AXES: tuple[str, str] = ("w_over_p", "A_ratio")
RECORD_X = "p"  # x of a record sweep (no w_over_p): the body's frequency parameter
LAM = "lam"  # the impulse position ratio, the diagrams' overlay dimension

#: alpha_ref of each body kind: (plain symbol and body key, LaTeX)
ALPHA_REF: dict[str, tuple[str, str]] = {"flexible": ("alpha_cg", r"\alpha_{cg}"),
                                         "block": ("alpha", r"\alpha")}
#: the body keys that hold alpha_ref, one per body kind (a Dataset has one of them)
ALPHA_KEYS: tuple[str, ...] = tuple(sym for sym, _ in ALPHA_REF.values())


def alpha_symbol(kind: str = "flexible") -> str:
    """Plain text of the body kind's alpha_ref, which is also the body key holding it:
    alpha_cg (flexible), alpha (block)."""
    return ALPHA_REF.get(kind, ALPHA_REF["block"])[0]


def alpha_latex(kind: str = "flexible") -> str:
    """LaTeX of the body kind's alpha_ref: alpha_cg (flexible), alpha (block)."""
    return ALPHA_REF.get(kind, ALPHA_REF["block"])[1]


def symbol(name: str, kind: str = "flexible") -> str:
    """The plain-text symbol of a swept key (its name if it has none), alpha_ref written as
    the body kind's slenderness."""
    meta = AXES.get(name)
    if meta is None:
        return name
    return meta.symbol.replace("alpha_ref", alpha_symbol(kind))


def latex(name: str, kind: str = "flexible") -> str:
    """The LaTeX symbol of a swept key (no dollars; ``\\mathrm{name}`` if it has none)."""
    meta = AXES.get(name)
    if meta is None:
        return r"\mathrm{" + name.replace("_", r"\_") + "}"
    return meta.latex.replace(r"\alpha_{ref}", alpha_latex(kind))


def label(name: str, kind: str = "flexible") -> str:
    """A figure's axis label: the symbol in math mode, then the units in brackets where
    the key has any (not for pure numbers and words)."""
    meta = AXES.get(name)
    units = meta.units if meta is not None else ""
    text = f"${latex(name, kind)}$" if meta is not None else name
    return text + (f" [{units}]" if units not in ("", "1") else "")
