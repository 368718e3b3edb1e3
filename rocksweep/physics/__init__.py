"""The model: bodies (Table 1's Pi groups -> SI), the impact law (eq. 1), excitations
(eq. 2 pulses, pulse families, recorded ground motions and their intensity measures), one
point's kernel parameter row, and the independent scipy reference path.

Modules: ``bodies`` (the bodies, restitution, eq. 6), ``excitation`` (pulse shapes),
``records`` (PEER .AT2 / two-column records), ``points`` (a point -> a kernel row, its
cost), ``reference`` (DOP853 + root finding, sharing only the equations with the kernel).
Nothing here reads or writes result files.
"""

# the public modules
__all__ = ["bodies", "excitation", "intensity", "points", "records", "reference"]
