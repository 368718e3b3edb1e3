"""The bootstrap's settings, shared by ``rocksweep.fragility``, the analysis
(``rocksweep.analysis.fragility``) and ``rocksweep fragility`` (one definition; this module
imports nothing heavy, so the command line reads it at start-up)."""

import numbers
from typing import Any

from rocksweep.errors import Arg, FragilityError

#: resamples over records when a caller gives none
DEFAULT_BOOTSTRAP = 200
#: at most this many resamples (each resample's fit is kept, 16 bytes a curve)
MAX_BOOTSTRAP = 100_000
#: the level of the bootstrap intervals and bands when a caller gives none
DEFAULT_CI = 0.9
#: the bootstrap's seed when a caller gives none
DEFAULT_SEED = 0


def check_ci(ci: Any) -> float:
    """The level of the bootstrap intervals, a number in (0, 1), or a ``FragilityError``."""
    if isinstance(ci, bool) or not isinstance(ci, numbers.Real) or not 0.0 < float(ci) < 1.0:
        raise FragilityError("{ci}: must be a number in (0, 1), e.g. 0.9", ci=Arg("ci", ci))
    return float(ci)
