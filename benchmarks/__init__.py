"""Benchmarks of impactsym, kept in the repository: ``python -m benchmarks SUBCOMMAND``.

* ``accuracy``: run time against error of every solution method (the generated
  kernels, their fastmath and float32 renderings, energy as a kinetic-energy
  difference, a per-row linear solve, ``sympy.lambdify``) on a realistic and a
  stress set; writes ``benchmarks/results/accuracy.md`` and ``accuracy.png``.

Run from the repository root (``impactsym.testing.reference`` is the 50-digit reference).
"""
