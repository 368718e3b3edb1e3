"""Every figure (``rocksweep.plot(ds)`` is the facade; ``by_kind`` picks a Dataset's
figure): ``style`` (the Figure class, journal widths, saving), ``restitution`` (Figure 2),
``diagrams`` (stability diagrams, Figures 3-4, and line plots of a sweep) over ``panels``
(the axes, panels and marks every diagram of a sweep shares), ``compare`` (one swept key's
values compared on one diagram), ``friction`` (the friction demand map), ``a_min`` (A_min
curves, the boundaries command's figure), ``history`` (time histories, Figure 5),
``spectrum`` (rocking and overturning spectra), ``fragility`` (fragility curves),
``results`` (risk, IDA, boundaries, IM efficiency), ``calibration``, ``accuracy``
(work-precision), ``pulses`` (the pulse shapes). Every figure is a
``rocksweep.figures.style.Figure`` (TrueType fonts in any saved PDF, a PNG in a notebook).
Figures are built without pyplot (``matplotlib.figure.Figure``), so nothing here needs a
display.
"""

# Figure files (the suffix picks the format) and raster resolution [dots per inch]: light
# constants, shared by the library's savers and the command line's options.
FORMATS = (".png", ".pdf", ".svg")
DEFAULT_DPI = 200
DPI_RANGE = (20, 2400)
# Figure widths for papers [inches] and the font size [pt] that keeps text legible when the
# figure is printed at that width: a single column (~88 mm) and a double column (~180 mm).
WIDTHS: dict[str, tuple[float, float]] = {"single": (3.5, 7.0), "double": (7.2, 8.0)}

# the public modules
__all__ = ["a_min", "accuracy", "by_kind", "calibration", "compare", "diagrams", "fragility",
           "friction", "history", "panels", "pulses", "restitution", "results", "spectrum",
           "style"]
