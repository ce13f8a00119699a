"""PLACEHOLDER until branch wt-trig lands: the sincos every angle path uses.

`SINCOS_SOURCE` is the source text of `def _sincos(x): ... return s, c`, valid
as plain Python and as numba code; `SINCOS_LIMIT` is the |x| up to which it is
accurate (beyond it the runtime takes the normal from NumPy's cos/sin). This
placeholder calls math.sin/math.cos; wt-trig replaces it with a vectorisable one.
"""

SINCOS_SOURCE = '''def _sincos(x):
    """(sin x, cos x) [x in rad]."""
    return math.sin(x), math.cos(x)
'''

SINCOS_LIMIT = 1.0e300
