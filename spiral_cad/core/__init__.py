"""Core numerics: the Bézier spiral, the five transitions (scalar and batch), chains, NURBS, units.

Needs only numpy, scipy and numba; nothing here imports a CAD kernel.
"""
