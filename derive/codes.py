"""Row status codes and physics flag bits shared by every generated kernel.

A kernel returns ``status`` (0 = solved; otherwise the row's outputs are NaN) and
``flags`` (a bit field that marks physically impossible results of a solved row).
The numbers are part of the public interface (conventions.md): never renumber.
"""

STATUS = {
    "OK": 0,
    "NONFINITE_INPUT": 1,
    "BAD_MASS": 2,
    "NOT_APPROACHING": 3,
    "SINGULAR": 4,
    "OVERFLOW": 5,
    "ENERGY_INCONSISTENT": 6,
    "INVERSE_E_TOO_SMALL": 7,
    "INVERSE_EM_TOO_SMALL": 8,
    "HEADINGS_COLLINEAR": 9,
    "RECONSTRUCT_FIXED": 10,
    "BAD_CRUSH": 11,
    "PDOF_BEYOND_LIMIT": 12,
    "NO_END_OF_COMPRESSION": 13,
    "BAD_FRICTION": 14,
}

FLAGS = {
    "ENERGY_CREATED": 1,
    "TENSILE_IMPULSE": 2,
    "MU_BEYOND_CRITICAL": 4,
    "E_OUT_OF_RANGE": 8,
    "NEGATIVE_SPEED": 16,
    "HEADINGS_ILL_CONDITIONED": 32,
    "PDOF_CAPPED": 64,
}
