"""Running points: the grid of a scene (``grid``), single runs with histories
(``single``), the dispatch of parameter rows to the compiled kernel variants and the
sweep drivers (``sweep``), and adaptive refinement near class boundaries (``adaptive``).
"""

# the public modules
__all__ = ["adaptive", "grid", "single", "sweep"]
