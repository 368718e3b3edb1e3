"""The project's enumerated concepts, each defined once, on the lowest floor (plain Python).

Everything that names a choice a user makes or reads back lives here, with the code the
kernel stores for it, its units and the paper's symbol; schema choices, click choices,
kernel codes, figure labels and stored attributes are derived from these tables
(tests/test_vocab.py fails when a list of these names is typed again elsewhere):

- ``ground``: pulse shapes (kernel codes, durations, the Ricker and MP formulas), the
  record shape, intensity measures (units, Sa's damping, default periods);
- ``laws``: impact laws (kernel codes, what each keeps, label of their e);
- ``axes``: the swept keys' names, units and symbols; the default diagram axes;
- ``outcomes``: outcome classes, status bits, fragility states, ``computed`` flags (their
  codes, words and meanings);
- ``settings``: accuracy preset, event root finder (with kernel codes) and ladder names,
  adaptive settings and their defaults, sweep backends;
- ``kinds``: the kinds of Dataset rocksweep writes and opens (``rocksweep_kind``).

No module here imports numpy, numba or another rocksweep module: every floor may read it.
"""
