"""Every figure (``rocksweep.plot(ds)`` is the facade): ``diagrams`` (stability
diagrams, Figures 3-4, friction maps, A_min), ``common`` (axes, saving, time histories
(Figure 5), the restitution map (Figure 2)), ``spectrum`` (rocking spectra),
``accuracy`` (work-precision), ``fragility`` (fragility curves), ``pulses`` (the pulse
shapes). Every figure is a ``rocksweep.figures.common.Figure`` (TrueType fonts in any
saved PDF, a PNG in a notebook). Figures are built
without pyplot (``matplotlib.figure.Figure``), so nothing here needs a display.
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
__all__ = ["accuracy", "common", "diagrams", "fragility", "pulses", "spectrum"]
