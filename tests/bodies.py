"""The paper's bodies (Tables 2 and 3), defined once for every test module.

FIG3: the flexible body of Figures 3 and 5 (omega_n/p = 2.43); FIG4: the stiff body of
Figure 4 (omega_n/p = 9.82); FIG2: the stocky body of Figure 2 (Table 2). Each as Pi groups
(a dict, keyword arguments of ``FlexibleBody``), as a scene's ``body:`` line (YAML flow
mapping), and as a body. ``table3(...)`` is FIG3 with some Pi groups changed.
"""

from __future__ import annotations

from rocksweep.physics.bodies import FlexibleBody

SHARED = {"zeta": 0.05, "alpha_cg": 0.15, "alpha_A": 0.28, "mA_over_m": 0.47,
          "IA_ratio": 0.56}
FIG3 = {"wn_over_p": 2.43, **SHARED}
FIG4 = {"wn_over_p": 9.82, **SHARED}
FIG2 = {**FIG3, "alpha_cg": 0.35, "alpha_A": 0.6}  # Table 2: Table 3's masses, stockier


def table3(**changes) -> dict:
    """FIG3's Pi groups with some changed (values may be YAML text, e.g. "[2.43, .inf]")."""
    return {**FIG3, **changes}


def body_yaml(pi: dict) -> str:
    """A scene's ``body:`` line for these Pi groups (YAML flow mapping, newline ended)."""
    return "body: {" + ", ".join(f"{k}: {v}" for k, v in pi.items()) + "}\n"


FIG3_YAML = body_yaml(FIG3)
BODY2 = FlexibleBody(**FIG2)
BODY3 = FlexibleBody(**FIG3)
BODY4 = FlexibleBody(**FIG4)
