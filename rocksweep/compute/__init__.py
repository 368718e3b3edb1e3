"""Running points: the grid of a scene (``grid``), single runs with histories
(``single``), the dispatch of parameter rows to the compiled kernel variants and the
in-memory array drivers (``sweep``), adaptive refinement near class boundaries
(``adaptive``), and the driver of a sweep into a result file or its in-memory image
(``driver``).
"""

# the public modules
__all__ = ["adaptive", "driver", "grid", "single", "sweep"]
