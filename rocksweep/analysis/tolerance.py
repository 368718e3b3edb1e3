"""The relative tolerance of a bisected threshold (A_min): its default. Its range and the
one check of it are ``rocksweep.errors.MAX_RTOL`` and ``check_rtol`` (the API, the CLI and
the analyses call it). A light module: the command line reads it while parsing options (no
numba, h5py or matplotlib)."""

from __future__ import annotations

DEFAULT_RTOL = 1e-3
#: the floor spectrum's A_min (``analysis.floors``): one bisection per building period and
#: value of the other keys, so a coarser default (its A_min to 1%)
FLOOR_RTOL = 1e-2
