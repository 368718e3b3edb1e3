"""The relative tolerance of a bisected threshold: its defaults. Its range and the one check
of it are ``rocksweep.errors.MAX_RTOL`` and ``check_rtol`` (the API, the CLI and the
analyses call it). A light module: the command line reads it while parsing options (no
numba, h5py or matplotlib)."""

from __future__ import annotations

#: A_min of a diagram or a spectrum (``boundaries``, ``spectra``): one bisection per curve
#: point
DEFAULT_RTOL = 1e-3
#: a threshold bisected per record or per floor period (``ida``, ``floor_spectrum``): many
#: bisections, each about three kernel runs cheaper than at DEFAULT_RTOL
DEFAULT_RTOL_MANY = 1e-2
