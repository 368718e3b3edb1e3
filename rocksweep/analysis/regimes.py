"""The contact regime of each run of a sweep with a sliding base (``body.mu``): which of the
four contact phases (``rocksweep.vocab.phases``: rest, slide, rock, slide-rock) it visited.

A sweep stores them per point in ``regime``, a bit set: bit ``1 << PHASE_CODE[phase]`` for
each phase the run entered. Its word (``regime_word``): "rest" where the run never left
rest (the rest bit alone, or no bit), else the phases it entered besides rest joined by
"+" in the phases' order ("slide", "rock", "slide-rock", "slide+rock", ...,
"slide+rock+slide-rock"): the eight ``REGIME_WORDS``. Shenton (1996) maps the phase a
rigid block enters from rest over mu and the amplitude; ``figures.regimes`` draws these
words over any two swept keys (``rocksweep.plot(regime=True)``, ``rocksweep plot
--regime``).
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from rocksweep.vocab.phases import PHASE_CODE, PHASES, REST

#: the result variable of the phases a run visited (a bit set)
REGIME = "regime"
#: the phases a run may enter after rest, in the phases' order
_MOVING = tuple(w for w in PHASES if w != REST)
#: every regime word, in drawing order: rest only, then the other phases' combinations,
#: one phase, two, all three
REGIME_WORDS: tuple[str, ...] = (REST, *("+".join(c) for k in range(1, len(_MOVING) + 1)
                                         for c in combinations(_MOVING, k)))
#: the largest bit set of the four phases (every bit)
MAX_REGIME = (1 << len(PHASES)) - 1


def regime_word(bits: int) -> str:
    """The regime word of a ``regime`` bit set (0 <= bits <= ``MAX_REGIME``)."""
    moving = [w for w in _MOVING if int(bits) & (1 << PHASE_CODE[w])]
    return "+".join(moving) if moving else REST


#: regime bit set -> index into REGIME_WORDS
_INDEX = np.array([REGIME_WORDS.index(regime_word(b)) for b in range(MAX_REGIME + 1)])


def regime_index(bits: np.ndarray) -> np.ndarray:
    """int64 array (bits' shape): the index into ``REGIME_WORDS`` of each bit set; -1 where
    it is not one (negative, above ``MAX_REGIME``, not an integer: NaN, a fill)."""
    v = np.asarray(bits, dtype=np.float64)
    ok = np.isfinite(v) & (v >= 0) & (v <= MAX_REGIME) & (v == np.round(v))
    return np.where(ok, _INDEX[np.where(ok, v, 0).astype(np.int64)], -1)
