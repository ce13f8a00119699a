"""Row status codes and physics flag bits, with the messages users see.

Batch results carry an integer ``status`` per row (0 = solved; otherwise the
row's outputs are NaN and the other rows are unaffected) and an integer
``flags`` bit field that marks physically impossible results of a solved row:

====== ======================================================================
status meaning
====== ======================================================================
0      solved
1      an input is NaN or infinite (only a fixed body's mass/inertia may be inf)
2      a mass or yaw inertia is not positive, or a body has infinite mass but
       finite inertia (or the reverse): a fixed body needs both infinite
3      the vehicles are not approaching at the impact centre, n·(u2 - u1) >= 0
4      singular: both bodies fixed, or the impact equations have no unique
       solution for these coefficients
5      a result overflowed (not finite)
6      delta-V from energy: the energy loss is negative or not consistent with
       the coefficients (no real delta-V)
7      inverse: restitution e is zero or below 2^-20, so the final velocities do
       not determine the normal approach speed
8      inverse: moment restitution |e_m| is zero or below 2^-20, so the final
       yaw rates do not determine the initial relative yaw rate
9      reconstruction: the headings are collinear (|sin(θ1 - θ2)| < 2^-20), so
       linear momentum does not determine the speeds
10     reconstruction: a vehicle is fixed (its momentum is undefined)
11     CRASH3: a crush input is out of range (A < 0, B <= 0, width <= 0 or a
       negative depth)
12     CRASH3: the PDOF is 90° or more from the inward normal of the damaged
       face (the force would pull the face out)
13     impact laws: a sliding contact whose compression never ends (the
       normal relative velocity does not reach zero while sliding)
14     impact laws: the friction coefficient is negative
====== ======================================================================

====== ======================================================================
flag   meaning (bits add up)
====== ======================================================================
1      energy created: TL < 0 or one of TLn, TLt, TLm < 0
2      tensile normal impulse: Pn >= 0 (a compressive impulse on vehicle 1
       points along -n)
4      impulse ratio beyond critical: mu not between 0 and mu_c
8      restitution e is outside [0, 1]: (reconstruction) the implied e; (forward and
       inverse kernels, a scene or a batch) the given e, on a solved row (a scene
       also warns, impactsym.result.scene_warnings)
16     (reconstruction) a speed is negative: the vehicle moved against its heading
32     (reconstruction) the headings are within about 6° of collinear
       (|sin(θ1 - θ2)| < 0.1): the speeds are sensitive to the headings
64     (CRASH3) the PDOF is more than 45° from the normal of the damaged face:
       the oblique correction was capped at 45° (EDCRASH caps 1 + tan²α at 2)
====== ======================================================================
"""

from __future__ import annotations

from ._kernels import CODES as _codes

STATUS_OK = _codes.STATUS_OK
FLAG_ENERGY_CREATED = _codes.FLAG_ENERGY_CREATED
FLAG_TENSILE_IMPULSE = _codes.FLAG_TENSILE_IMPULSE
FLAG_MU_BEYOND_CRITICAL = _codes.FLAG_MU_BEYOND_CRITICAL
FLAG_E_OUT_OF_RANGE = _codes.FLAG_E_OUT_OF_RANGE
FLAG_NEGATIVE_SPEED = _codes.FLAG_NEGATIVE_SPEED
FLAG_HEADINGS_ILL_CONDITIONED = _codes.FLAG_HEADINGS_ILL_CONDITIONED
FLAG_PDOF_CAPPED = _codes.FLAG_PDOF_CAPPED

STATUS_MESSAGES = {
    _codes.STATUS_OK: "solved",
    _codes.STATUS_NONFINITE_INPUT: "an input is NaN or infinite "
    "(only a fixed body's mass and yaw inertia may be infinite)",
    _codes.STATUS_BAD_MASS: "a mass or yaw inertia is not a positive number, or a body has "
    "infinite mass but finite yaw inertia (a fixed body needs both infinite)",
    _codes.STATUS_NOT_APPROACHING: "the vehicles are not approaching at the impact centre "
    "(n·(u2 - u1) >= 0; n must point from vehicle 1 toward vehicle 2)",
    _codes.STATUS_SINGULAR: "singular impact equations (both bodies fixed, or no unique "
    "impulse for these coefficients)",
    _codes.STATUS_OVERFLOW: "a result is not finite (overflow)",
    _codes.STATUS_ENERGY_INCONSISTENT: "the energy loss is negative or not consistent with "
    "the coefficients e, mu and r (no real delta-V)",
    _codes.STATUS_INVERSE_E_TOO_SMALL: "restitution e is zero or below 2^-20: the final "
    "velocities do not determine the normal approach speed (e appears in the denominator); "
    "give the pre-impact headings (impactsym reconstruct) or the energy loss "
    "(impactsym.delta_v_from_energy) instead",
    _codes.STATUS_HEADINGS_COLLINEAR: "the pre-impact headings are collinear (or within "
    "2^-20 rad): linear momentum does not determine the speeds; use the inverse solution "
    "with restitution and impulse ratio (impactsym invert) instead",
    _codes.STATUS_RECONSTRUCT_FIXED: "a reconstruction needs two moving vehicles (a fixed "
    "body's momentum is undefined)",
    _codes.STATUS_INVERSE_EM_TOO_SMALL: "moment restitution e_m is zero or below 2^-20 in "
    "magnitude: the final yaw rates do not determine the initial relative yaw rate; give the "
    "pre-impact yaw rates (impactsym reconstruct) or use e_m = 1 (no moment impulse)",
    _codes.STATUS_BAD_CRUSH: "a CRASH3 crush input is out of range: A must be >= 0, B and "
    "the width > 0, every depth >= 0",
    _codes.STATUS_PDOF_BEYOND_LIMIT: "the PDOF is 90 degrees or more from the inward normal of "
    "the damaged face: the force would pull the face out",
    _codes.STATUS_NO_END_OF_COMPRESSION: "the sliding contact's compression never ends: with this "
    "friction the normal relative velocity at the impact centre does not reach zero while sliding",
    _codes.STATUS_BAD_FRICTION: "the friction coefficient at the impact centre is negative",
}

FLAG_MESSAGES = {
    FLAG_ENERGY_CREATED: "energy created: the energy loss or one of its parts is negative, "
    "which is physically impossible (check the impulse ratio and restitution)",
    FLAG_TENSILE_IMPULSE: "tensile normal impulse: the vehicles would pull on each other",
    FLAG_MU_BEYOND_CRITICAL: "impulse ratio mu is not between 0 and the critical ratio mu_c: "
    "the friction impulse would reverse the sliding (seed Table 2)",
    FLAG_E_OUT_OF_RANGE: "restitution e is outside [0, 1], which is not physical (a "
    "reconstruction's implied e: the post-impact motion, headings or impact centre are "
    "inconsistent; a given e: e < 0 leaves the vehicles moving into each other, "
    "e > 1 creates energy)",
    FLAG_NEGATIVE_SPEED: "a reconstructed speed is negative: the vehicle would have moved "
    "against its stated heading",
    FLAG_HEADINGS_ILL_CONDITIONED: "the headings are within about 6 degrees of collinear: "
    "the reconstructed speeds are very sensitive to the headings",
    FLAG_PDOF_CAPPED: "the PDOF is more than 45 degrees from the normal of the damaged face: "
    "the oblique energy correction was capped at 45 degrees (EDCRASH caps 1 + tan^2(alpha) at 2)",
}


def describe_status(status: int) -> str:
    """The message for a row status code."""
    return STATUS_MESSAGES.get(int(status), f"unknown status {int(status)}")


def describe_flags(flags: int) -> list[str]:
    """One message per flag bit set in `flags`, lowest bit first."""
    return [msg for bit, msg in sorted(FLAG_MESSAGES.items()) if int(flags) & bit]
