"""SymPy derivations of the impact models of Brach's review (the seed paper).

This package is the only place formulas are written. Each model module
(`particle`, `planar`, ...) derives its closed forms from the governing equations,
proves them symbolically, and describes the kernels to emit; `emit` turns those
descriptions into numba code in ``generated/``. Run ``python -m derive`` to
regenerate and ``python -m derive --check`` to verify ``generated/`` is current.
"""
