"""Running points: the sweep session (``session``: the one way in for ``rocksweep.run`` and
``rocksweep sweep``) over its checked arguments (``arguments``) and the driver of a sweep
into a result file or its in-memory image (``driver``); a chunk's rows per kernel variant,
workers and dask (``sweep``), the dispatch of parameter rows to the compiled variants
(``dispatch``), close calls certified (``certify``), adaptive refinement near class
boundaries (``adaptive``), single runs with histories (``single``, ``history``).
"""

# the public modules
__all__ = ["adaptive", "arguments", "certify", "dispatch", "driver", "history", "session",
           "single", "sweep"]
