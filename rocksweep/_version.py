"""rocksweep's version: the one definition (pyproject.toml reads it, ``[tool.setuptools.dynamic]``;
``rocksweep.__version__`` and every file's ``rocksweep_version`` attribute give it)."""

__version__ = "0.2.0"
