"""Test support shared by tests/, benchmarks/ and notebooks/: not runtime code.

- `impactsym.testing.reference`: the independent 50-digit reference solver
  (mpmath, a ``test`` extra), which shares no algebra with the closed forms.
- `impactsym.testing.scenes`: generators of random and hard scenes as batch columns.

Neither is imported by ``import impactsym``, and neither imports ``derive`` or
``generated``: they check the generated kernels from outside. Not in the wheel
(pyproject.toml): they serve a checkout or an sdist, where mpmath comes with the
``test`` extra.
"""
