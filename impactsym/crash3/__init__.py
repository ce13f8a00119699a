"""CRASH3: delta-V from crush energy, and its inconsistency with impulse-momentum.

The formulas are derive/crash3.py's (emitted to generated/crash3.py): crush energy
of each vehicle from its damage profile, the oblique correction (CRASH3's
1 + tan²α or Woolley's 1/cos α, capped at α = 45° as EDCRASH does), the
effective-mass factor γ = k²/(k² + h²), and delta-V from the total energy with
a common velocity (restitution e = 0 unless given).

A vehicle's ``crush`` table (scene file):

- ``A`` [N/m | lb/in], ``B`` [N/m² | lb/in²]: stiffness, F/w = A + B·C;
- ``width`` [m | in]: damage width L; ``depths`` [m | in]: 2, 4 or 6 equally
  spaced crush depths C1..CN across it (piecewise linear between them);
- ``pdof`` [deg]: the principal direction of force on the vehicle, measured
  from the inward normal of its damaged face, counter-clockwise positive; the
  damaged face is the crush surface of ``impact.normal_angle``, so the inward
  normal is -n for vehicle 1 and +n for vehicle 2, and the force on vehicle 1
  points along Γ + 180° + α (on vehicle 2 along Γ + α);
- optional ``moment_arm`` [m | ft] (h, the distance from the centre of gravity
  to the PDOF line) and ``radius_of_gyration`` [m | ft] (k);
- instead of ``A`` and ``B``: ``category`` (1-9) and ``face`` (``front``,
  ``rear``, ``side``), the EDCRASH default stiffness of
  :mod:`impactsym.crash3.tables` (Day & Hargens, SAE 870045); a scene may mix
  categories and explicit A, B; ``class`` (1-7, 10) supplies the class default
  k² when the vehicle has no ``yaw_inertia`` and no ``radius_of_gyration``.

Options (the scene's top-level ``"crash3"`` object; the arguments of
:func:`crash3` and the CLI flags of the same names override it):

- ``restitution`` e (default 0: CRASH3's common velocity);
- ``energy``: ``"dissipated"`` (default: the crush energy is the energy lost
  over the whole impact, |P| = √(2 E m̄ (1 + e)/(1 - e))) or ``"absorbed"`` (the
  crush energy is absorbed up to maximum crush: the approach delta-V comes from
  it, |P| = (1 + e)·√(2 E m̄); Rose, Fenton & Beauchamp, SAE 2006-01-0908);
- ``correction``: ``"crash3"`` (default, E·(1 + tan²α)) or ``"woolley"``
  (E/cos α). Both are capped as EDCRASH caps CRASH3's factor at 2: the angle
  is taken as min(|α|, 45°) and a capped vehicle gets a warning; |α| ≥ 90° is
  an error.

Which delta-V: ``delta_v_magnitude`` is the change of velocity of the centre of
gravity, |P|/m (what Brach, Neades and Rose report and a CG accelerometer
measures). ``delta_v_effective_mass`` is EDCRASH's printed value, the change of
velocity of the effective mass γ·m, |P|/(γ m); the two are related by
ΔV_cg = γ·ΔV_eff with γ = k²/(k² + h²) (derive/crash3.py proves it).

A crash3 scene needs no ``impact`` block: without it the delta-V has no
direction in the scene frame (``delta_v`` is null), moment arms must be given
as ``moment_arm`` (or are 0), and there is no impulse-momentum comparison.

Units: SI crush inputs give joules. US crush inputs are CRASH3's lb/in, lb/in²
and in (pounds of force; masses stay in slugs): their energy is in in·lb and is
divided by ``INCHES_PER_FOOT`` = 12 to give ft·lb. Moment arm and radius of
gyration are in the scene's length unit (m | ft).

Without ``moment_arm`` the arm is computed from ``impact_point`` (when given) and
the PDOF; without ``radius_of_gyration`` it comes from ``yaw_inertia`` and
``mass`` (when given). Missing either, γ = 1 (no effective-mass correction).

When the scene also has the motion of a forward scene (velocities, yaw
inertias, impact points), the common-velocity impulse-momentum solution of the
same scene (e_m = 1, the same restitution) gives the PDOF CRASH3's own |ΔV|
assumption implies, α = atan2(-Pt, -Pn) with tan α = μ_c: the seed's
criticism (CRASH takes |ΔV| from μ = μ_max but its direction from the user's
PDOF) is reported as the difference between the two.
"""

from .crush import crash3_options, crush_tables
from .model import (
    CORRECTIONS,
    ENERGY_MODES,
    INCHES_PER_FOOT,
    PDOF_CAP_DEG,
    PDOF_MISMATCH_DEG,
    Crash3Options,
    Crash3Result,
    Crash3Vehicle,
    Crush,
)
from .run import crash3

__all__ = [
    "crash3",
    "Crash3Result",
    "Crash3Vehicle",
    "Crash3Options",
    "crash3_options",
    "Crush",
    "crush_tables",
    "INCHES_PER_FOOT",
    "PDOF_MISMATCH_DEG",
    "ENERGY_MODES",
    "CORRECTIONS",
    "PDOF_CAP_DEG",
]
